"""The diagnosis report: the before/after table, report.md and its plots.

Reads the content of report.json (INTERFACE.md) and the simulated series; decides nothing. The
residual is r = T_air,measured - T_air,simulated (PHYSICS.md section 6), so a positive mean means
the model is too cold. The tables follow Lauret et al.: Table 4 (J with each node forced alone)
for the localisation, Table 5 (mean and standard deviation of the residual, before and after the
correction) for the result, with RMSE and n added.

Every number may be missing (None or NaN, e.g. J of a simulation that failed): it is written
"n/a" and left out of the plots. The plots are drawn on matplotlib Figure objects with the Agg
canvas, so writing a report changes no global matplotlib state (no pyplot, no backend switch).
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib import dates as mdates
from matplotlib import patheffects
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import Patch
from matplotlib.ticker import MaxNLocator

WINDOWS = ("calibration", "validation")
NA = "n/a"

# units of the parameters of PHYSICS.md section 7 (for the plots and tables; unknown: none)
UNITS = {
    ("ground_coupling", "U"): "W/m2/K",
    ("ground_coupling", "T_ground"): "C",
    ("infiltration", "n"): "1/h",
    ("internal_gain", "Q"): "W",
}

PLOTS = {
    "temperature": "air_temperature.png",
    "residuals": "residuals.png",
    "node_scores": "node_scores.png",
    "convergence": "convergence.png",
    "candidates": "candidates.png",
}

COLOR_MEASURED = "black"
COLOR_BEFORE = "tab:red"
COLOR_AFTER = "tab:blue"
COLOR_VALIDATION = "0.88"


# ---------------------------------------------------------------------------------------------
# numbers


def _num(x):
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
    v = _num(x)
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
    v = _num(x)
    if v is None:
        return NA
    return f"{v:+.3f}" if signed else f"{v:.3f}"


def fmt_int(x):
    v = _num(x)
    return NA if v is None else str(int(round(v)))


def fmt_value_std(value, std, pm="±"):
    """value ± std, the value to the precision of its std (2 significant digits of the std)."""
    v, s = _num(value), _num(std)
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


def _param_entries(parameters):
    """[(name, value, std, identifiable)] from PARAMS (a bare number is a value without std)."""
    out = []
    for name, p in (parameters or {}).items():
        if isinstance(p, dict):
            ident = p.get("identifiable")
            out.append((name, p.get("value"), p.get("std"), True if ident is None else bool(ident)))
        else:
            out.append((name, p, None, True))
    return out


def fmt_parameters(effect, parameters, pm="±"):
    """'U = 0.52 ± 0.03 W/m2/K, T_ground = 24 ± 9 C (not identifiable)'; '' for no parameter."""
    parts = []
    for name, value, std, ident in _param_entries(parameters):
        unit = UNITS.get((effect, name))
        text = f"{name} = {fmt_value_std(value, std, pm)}" + (f" {unit}" if unit else "")
        if not ident:
            text += " (not identifiable)"
        parts.append(text)
    return ", ".join(parts)


def _is_none_effect(effect):
    return not effect or effect.get("effect") in (None, "none")


def _effect_name(effect, target):
    return f"{effect} on {target}" if target not in (None, "") else str(effect)


def _metrics(report, state, window):
    m = (report.get(state) or {}).get(window)
    return m if isinstance(m, dict) else {}


def _time_text(iso):
    """'2001-06-10 00:00 UTC-05:00' from an ISO 8601 string (kept as is when unreadable)."""
    try:
        t = pd.Timestamp(iso)
    except (TypeError, ValueError):
        return str(iso) if iso is not None else NA
    text = t.strftime("%Y-%m-%d %H:%M")
    return text + (f" {_utc_offset(t)}" if t.tzinfo is not None else "")


def _utc_offset(t):
    z = t.strftime("%z")  # +hhmm
    return f"UTC{z[:3]}:{z[3:]}" if z else "UTC"


def _period_text(report, window):
    span = (report.get("period") or {}).get(window)
    if not span or len(span) != 2:
        return NA
    return f"{_time_text(span[0])} to {_time_text(span[1])}"


# ---------------------------------------------------------------------------------------------
# the decision, read back (the pipeline makes it; the report explains it)


def _beats_bic(candidate):
    bic, base = _num(candidate.get("bic")), _num(candidate.get("bic_baseline"))
    return bic is not None and base is not None and bic < base


def _val_rmse(candidate):
    return _num((candidate.get("validation") or {}).get("rmse"))


def _is_chosen(candidate, effect):
    return (not _is_none_effect(effect) and candidate.get("effect") == effect.get("effect")
            and candidate.get("target") == effect.get("target"))


def effect_header(report, pm="+-"):
    """The line naming the chosen effect, its target and parameters, or 'none: ...'."""
    effect = report.get("effect") or {}
    if _is_none_effect(effect):
        return "Effect added: none: no effect improves the validation error"
    params = fmt_parameters(effect.get("effect"), effect.get("parameters"), pm)
    line = f"Effect added: {_effect_name(effect.get('effect'), effect.get('target'))}" + (f": {params}" if params else "")
    for name, d in (effect.get("derived") or {}).items():
        line += (f"\n  the data determine {name.replace('_', ' ')} = "
                 f"{fmt_value_std(d.get('value'), d.get('std'), pm)} {d.get('unit', '')}".rstrip())
    return line


def _bold_lines(text):
    """Markdown: each line of `text` in bold, as its own paragraph line."""
    return [f"**{line.strip()}**  " for line in text.splitlines()]


def rationale(report):
    """One sentence: why this effect (or none) was chosen, from the candidates' numbers."""
    effect = report.get("effect") or {}
    candidates = report.get("candidates") or []
    before_val = _num(_metrics(report, "before", "validation").get("rmse"))
    beating = [c for c in candidates if _beats_bic(c)]
    if _is_none_effect(effect):
        if not candidates:
            return "No candidate effect was tried, so the model is left as it is."
        better = [c for c in beating if _val_rmse(c) is not None and before_val is not None and _val_rmse(c) < before_val]
        if not beating:
            return (f"None of the {len(candidates)} candidates lowers the BIC below the baseline's, "
                    "so no effect is added: no effect improves the validation error.")
        if not better:
            return (f"{len(beating)} of the {len(candidates)} candidates lower the BIC, but none lowers the "
                    f"validation RMSE below the baseline's {fmt_temp(before_val)} C: no effect is added.")
        best = min(better, key=_val_rmse)
        return (f"{len(beating)} of the {len(candidates)} candidates lower the BIC, but the best, "
                f"{_effect_name(best.get('effect'), best.get('target'))}, lowers the validation RMSE only from "
                f"{fmt_temp(before_val)} C to {fmt_temp(_val_rmse(best))} C, within the noise: no effect is added.")
    chosen = next((c for c in candidates if _is_chosen(c, effect)), None)
    name = _effect_name(effect.get("effect"), effect.get("target"))
    if chosen is None:
        return f"{name} was chosen by the diagnosis (it is not among the candidates listed)."
    rmse = _val_rmse(chosen)
    best = min((c for c in beating if _val_rmse(c) is not None), key=_val_rmse, default=None)
    if best is chosen:
        return (f"{name} has the lowest validation RMSE ({fmt_temp(rmse)} C, {fmt_temp(before_val)} C "
                f"before) of the {len(beating)} of {len(candidates)} candidates whose BIC beats the "
                f"baseline's ({fmt_bic(chosen.get('bic'))} < {fmt_bic(chosen.get('bic_baseline'))}).")
    return (f"{name} was chosen by the diagnosis: validation RMSE {fmt_temp(rmse)} C ({fmt_temp(before_val)} C "
            f"before), BIC {fmt_bic(chosen.get('bic'))} (baseline {fmt_bic(chosen.get('bic_baseline'))}).")


# ---------------------------------------------------------------------------------------------
# the before/after table (terminal)


def before_after_table(report: dict) -> str:
    """The before/after table printed by `nodeforce demo`/`diagnose`: rows calibration and validation windows, columns RMSE, mean, sd of the air residual (C) and n, before and after; a header line naming the chosen effect, target and its parameters (value +- std, 'not identifiable' flagged), or 'none: no effect improves the validation error'."""
    cols = ("RMSE", "mean", "sd", "n")
    width = 8
    group = len(cols) * (width + 1) - 1
    lines = [effect_header(report, pm="+-"),
             "Air residual r = measured - simulated (C)",
             f"{'':<12} | {'before':^{group}} | {'after':^{group}}",
             f"{'window':<12} | " + " ".join(f"{c:>{width}}" for c in cols)
             + " | " + " ".join(f"{c:>{width}}" for c in cols)]
    lines.append("-" * len(lines[-1]))
    for window in WINDOWS:
        cells = []
        for state in ("before", "after"):
            m = _metrics(report, state, window)
            cells.append(" ".join(f"{v:>{width}}" for v in (
                fmt_temp(m.get("rmse")), fmt_temp(m.get("mean"), signed=True), fmt_temp(m.get("sd")), fmt_int(m.get("n")))))
        lines.append(f"{window:<12} | {cells[0]} | {cells[1]}")
    for window in WINDOWS:
        lines.append(f"{window}: {_period_text(report, window)}")
    return "\n".join(lines)


# ---------------------------------------------------------------------------------------------
# plots


def _new_figure(width=10.0, height=4.8):
    fig = Figure(figsize=(width, height), layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def _save(fig, path):
    fig.savefig(path, dpi=110)
    return path


def _local_times(times):
    """Naive wall-clock times (plotted as read on site) and the axis label naming the offset."""
    times = pd.DatetimeIndex(times)
    if times.tz is None:
        return times, "time"
    return times.tz_localize(None), f"time ({_utc_offset(times[0])})"


def _local_instant(t, times):
    if t is None:
        return None
    t = pd.Timestamp(t)
    tz = pd.DatetimeIndex(times).tz
    if t.tzinfo is not None:
        t = t.tz_convert(tz).tz_localize(None) if tz is not None else t.tz_localize(None)
    return t


def _date_axis(ax, xlabel):
    locator = mdates.AutoDateLocator()
    ax.xaxis.set_major_locator(locator)
    ax.xaxis.set_major_formatter(mdates.ConciseDateFormatter(locator))
    ax.set_xlabel(xlabel)


def _shade_validation(ax, start, end):
    if start is None or end is None or start >= end:
        return
    ax.axvspan(start, end, color=COLOR_VALIDATION, zorder=0, label="validation window")


def _burn_in_end(report, series, times_local):
    """The first scored time of the calibration window (local), when a burn-in precedes it."""
    scored = (report.get("period") or {}).get("calibration_scored_from")
    try:
        t = _local_instant(scored, series["times"])
    except (TypeError, ValueError):
        return None
    return t if t is not None and len(times_local) and t > times_local[0] else None


def _shade_burn_in(ax, t0, scored_from):
    if scored_from is not None:
        ax.axvspan(t0, scored_from, facecolor="none", edgecolor="0.7", hatch="//", lw=0, zorder=0,
                   label="burn-in (not scored)")


def _label_windows(ax, t0, start, end):
    """'calibration' and 'validation' written at the top of their windows."""
    if start is None:
        return
    trans = ax.get_xaxis_transform()
    style = dict(transform=trans, va="top", fontsize=9, color="0.35",
                 bbox=dict(facecolor="white", edgecolor="none", alpha=0.7, pad=1))
    if t0 < start:
        ax.text(t0 + (start - t0) / 2, 0.98, "calibration", ha="center", **style)
    if start < end:
        ax.text(start + (end - start) / 2, 0.98, "validation", ha="center", **style)


def _array(series, key, n):
    a = series.get(key)
    if a is None:
        return None
    a = np.asarray(a, dtype=float).reshape(-1)
    return a if len(a) == n else None


def _same(a, b):
    return a is not None and b is not None and np.array_equal(a, b, equal_nan=True)


def _window_masks(times_local, start, scored_from=None):
    """The scored steps of each window (the burn-in, before scored_from, is in neither)."""
    n = len(times_local)
    val = np.zeros(n, bool) if start is None else np.asarray(times_local >= start)
    cal = ~val & (np.ones(n, bool) if scored_from is None else np.asarray(times_local >= scored_from))
    return {"calibration": cal, "validation": val}


def _residual_stats(report, state, window, residual, mask):
    """mean and sd of the residual in a window: report.json's, else computed from the series."""
    m = _metrics(report, state, window)
    mean, sd = _num(m.get("mean")), _num(m.get("sd"))
    if (mean is None or sd is None) and residual is not None:
        r = residual[mask & np.isfinite(residual)]
        if len(r) > 1:
            mean, sd = float(r.mean()), float(r.std(ddof=1))
    return mean, sd


def _finish_time_plot(fig, ax, path, windows, xlabel, ylabel, title, legend_columns):
    """Window labels, axes, grid and the legend below, shared by the plots against time."""
    _label_windows(ax, *windows)
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    _date_axis(ax, xlabel)
    ax.grid(alpha=0.3)
    ax.margins(x=0)
    fig.legend(loc="outside lower center", ncols=legend_columns, fontsize=9, frameon=False)
    return _save(fig, path)


def _time_plot(report, series):
    """What both plots against time start from: the figure with its burn-in and validation
    shading, local times, the validation start, the scored start, the measured, before and
    after series, and whether after is the same as before."""
    times, xlabel = _local_times(series["times"])
    n = len(times)
    start = _local_instant(series.get("validation_start"), series["times"])
    arrays = tuple(_array(series, k, n) for k in ("measured", "before", "after"))
    unchanged = _is_none_effect(report.get("effect")) or _same(arrays[1], arrays[2])
    scored_from = _burn_in_end(report, series, times)
    fig = _new_figure()
    ax = fig.add_subplot()
    _shade_burn_in(ax, times[0], scored_from)
    _shade_validation(ax, start, times[-1] if n else None)
    return fig, ax, times, xlabel, start, scored_from, arrays, unchanged


def plot_temperature(path, report, series):
    """Measured and simulated air temperature, before and after, validation window shaded."""
    fig, ax, times, xlabel, start, scored_from, (measured, before, after), unchanged = _time_plot(report, series)
    air = series.get("air_node")
    if before is not None:
        label = "simulated (no effect added)" if unchanged else "simulated before"
        ax.plot(times, before, color=COLOR_BEFORE, lw=1.4, label=label)
    if after is not None and not unchanged:
        ax.plot(times, after, color=COLOR_AFTER, lw=1.4, label=f"simulated after ({_effect_label(report)})")
    if measured is not None:
        ax.plot(times, measured, color=COLOR_MEASURED, lw=0, marker=".", ms=2.5, label="measured")
    node = f" (node {air})" if air is not None else ""
    return _finish_time_plot(fig, ax, path, (scored_from or times[0], start, times[-1]), xlabel,
                             "indoor air temperature (C)", f"Indoor air temperature{node}: measured and simulated", 4)


def _effect_label(report):
    e = report.get("effect") or {}
    return "no effect" if _is_none_effect(e) else _effect_name(e.get("effect"), e.get("target"))


def plot_residuals(path, report, series):
    """Residual before and after over time, mean and sd per window in the legend (Table 5)."""
    fig, ax, times, xlabel, start, scored_from, (measured, before, after), unchanged = _time_plot(report, series)
    masks = _window_masks(times, start, scored_from)
    ax.axhline(0, color="0.4", lw=0.8)
    states = [("before", before, COLOR_BEFORE)] + ([] if unchanged else [("after", after, COLOR_AFTER)])
    segments = []
    for state, simulated, color in states:
        if simulated is None or measured is None:
            continue
        r = measured - simulated
        stats = []
        for window in WINDOWS:
            mean, sd = _residual_stats(report, state, window, r, masks[window])
            if masks[window].any():
                stats.append(f"{window[:3]}. mean {fmt_temp(mean, True)}, sd {fmt_temp(sd)}")
                if mean is not None:  # the window's mean as a dashed segment over its scored steps
                    t_w = times[masks[window]]
                    segments.append(([t_w[0], t_w[-1]], [mean, mean], color))
        name = "no effect added" if unchanged else state
        ax.plot(times, r, color=color, lw=0.9, alpha=0.85, label=f"{name}: " + "; ".join(stats) + " C")
    outline = [patheffects.withStroke(linewidth=4, foreground="white")]
    for x, y, color in segments:
        ax.plot(x, y, color=color, lw=2, ls="--", zorder=5, path_effects=outline)
    ax.plot([], [], color="0.3", ls="--", lw=2, label="mean over the window (scored steps)")
    return _finish_time_plot(fig, ax, path, (scored_from or times[0], start, times[-1]), xlabel,
                             "residual measured - simulated (C)", "Indoor air residual before and after the correction", 2)


def _node_sort_key(node):
    try:
        return (0, int(node), "")
    except (TypeError, ValueError):
        return (1, 0, str(node))


def plot_node_scores(path, report, labels=None):
    """J with each node forced alone, J unforced as a line, best_nodes highlighted (Table 4)."""
    loc = report.get("localization") or {}
    scores = loc.get("node_scores") or {}
    nodes = sorted(scores, key=_node_sort_key)
    best = {str(b) for b in (loc.get("best_nodes") or [])}
    values = [_num(scores[k]) for k in nodes]
    J_unforced = _num(loc.get("J_unforced"))
    finite = [v for v in values if v is not None and v > 0]
    # linear shows best how much of J a forcing removes; log only when some forcing makes J explode
    if J_unforced:
        log = bool(finite) and max(finite) > 5 * J_unforced
    else:
        log = bool(finite) and max(finite) / min(finite) > 30
    fig = _new_figure(max(7.0, 0.45 * len(nodes) + 3), 4.8)
    ax = fig.add_subplot()
    x = np.arange(len(nodes))
    heights = [v if v is not None else 0 for v in values]
    colors = ["tab:orange" if k in best else "tab:gray" for k in nodes]
    ax.bar(x, heights, color=colors, edgecolor="0.2", lw=0.5)
    for xi, v in zip(x, values):
        if v is None:
            ax.text(xi, 0.02, "failed", transform=ax.get_xaxis_transform(), rotation=90,
                    ha="center", va="bottom", fontsize=8, color="tab:red")
        elif J_unforced:
            ax.annotate(f"{100 * v / J_unforced:.0f}%", (xi, v), xytext=(0, 3), textcoords="offset points",
                        ha="center", va="bottom", fontsize=7.5,
                        bbox=dict(facecolor="white", edgecolor="none", alpha=0.8, pad=0.5))
    if J_unforced is not None:
        ax.axhline(J_unforced, color="black", ls="--", lw=1.2, label=f"J unforced = {fmt_sig(J_unforced)} C²")
    J_best = _num(loc.get("J_best"))
    if J_best is not None and best:
        ax.axhline(J_best, color="tab:orange", ls=":", lw=1.2,
                   label=f"J with best_nodes ({', '.join(sorted(best, key=_node_sort_key))}) forced = {fmt_sig(J_best)} C²")
    handles, _ = ax.get_legend_handles_labels()
    if best:
        handles.append(Patch(facecolor="tab:orange", edgecolor="0.2", label="in best_nodes"))
    handles.append(Patch(facecolor="tab:gray", edgecolor="0.2", label="other node" if best else "node (best_nodes = [])"))
    ticks = [str(k) if not labels or str(k) not in labels else f"{k}\n{labels[str(k)]}" for k in nodes]
    ax.set_xticks(x, ticks, fontsize=8 if labels else 9)
    ax.set_xlabel("node forced alone to its measurement")
    ax.set_ylabel("J = sum of squared air residuals (C²)" + (", log scale" if log else ""))
    if log:
        ax.set_yscale("log")
    ax.set_title("Localisation: J with each node forced alone")
    ax.grid(axis="y", alpha=0.3)
    if J_unforced and any(v is not None for v in values):
        handles.append(Patch(facecolor="none", edgecolor="none", label="above the bars: J as % of J unforced"))
    fig.legend(handles=handles, loc="outside lower center", ncols=2, fontsize=9, frameon=False)
    return _save(fig, path)


def _convergence_points(convergence):
    pts = []
    for item in convergence or []:
        try:
            g, J = item[0], item[1]
        except (TypeError, IndexError, KeyError):
            continue
        g, J = _num(g), _num(J)
        if g is not None and J is not None:
            pts.append((g, J))
    return pts


def plot_convergence(path, report, series):
    """Best J so far against the generation of the GA (or the batch, for an exhaustive search)."""
    pts = _convergence_points(series.get("convergence"))
    loc = report.get("localization") or {}
    search = loc.get("search") or {}
    g, J = np.array([p[0] for p in pts]), np.array([p[1] for p in pts])
    fig = _new_figure(8.0, 4.5)
    ax = fig.add_subplot()
    ax.step(g, J, where="post", color="tab:blue", lw=1.6, marker="o", ms=3, label="best J so far")
    J_unforced = _num(loc.get("J_unforced"))
    if J_unforced is not None:
        ax.axhline(J_unforced, color="black", ls="--", lw=1.2, label=f"J unforced = {fmt_sig(J_unforced)} C²")
    J_min = _num(search.get("J_min"))
    if J_min is not None:
        ax.axhline(J_min, color="tab:green", ls=":", lw=1.2, label=f"J min = {fmt_sig(J_min)} C²")
    positive = [v for v in list(J) + [J_unforced or 0] if v and v > 0]
    if positive and max(positive) / min(positive) > 30:
        ax.set_yscale("log")
    exhaustive = search.get("method") == "exhaustive"
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.set_xlabel("batch of evaluations" if exhaustive else "generation")
    ax.set_ylabel("best J so far (C²)")
    bits = [f"{k} {search[k]}" for k in ("population", "pc", "pm", "seed") if search.get(k) is not None]
    ax.set_title("Exhaustive search: best J per batch" if exhaustive else
                 "GA convergence" + (f" ({', '.join(bits)})" if bits else ""))
    ax.grid(alpha=0.3)
    ax.legend(fontsize=9, framealpha=0.9)
    return _save(fig, path)


def plot_candidates(path, report):
    """Validation RMSE of each candidate against the baseline (before) validation RMSE."""
    candidates = report.get("candidates") or []
    effect = report.get("effect") or {}
    base = _num(_metrics(report, "before", "validation").get("rmse"))
    fig = _new_figure(max(7.0, 1.1 * len(candidates) + 3), 4.8)
    ax = fig.add_subplot()
    x = np.arange(len(candidates))
    for xi, c in zip(x, candidates):
        v = _val_rmse(c)
        if v is None:
            ax.text(xi, 0.02, "failed", transform=ax.get_xaxis_transform(), ha="center", va="bottom",
                    fontsize=8, color="tab:red")
            continue
        if _is_chosen(c, effect):
            style = dict(color="tab:blue")
        elif _beats_bic(c):
            style = dict(color="tab:cyan")
        else:
            style = dict(color="0.8", hatch="//")
        ax.bar(xi, v, edgecolor="0.2", lw=0.5, **style)
        bic, base_bic = _num(c.get("bic")), _num(c.get("bic_baseline"))
        dbic = f"\nΔBIC {bic - base_bic:+.1f}" if bic is not None and base_bic is not None else ""
        ax.annotate(fmt_temp(v) + dbic, (xi, v), xytext=(0, 3), textcoords="offset points", ha="center",
                    va="bottom", fontsize=8, bbox=dict(facecolor="white", edgecolor="none", alpha=0.8, pad=0.5))
    if base is not None:
        ax.axhline(base, color="tab:red", ls="--", lw=1.2, label=f"baseline (no effect) = {fmt_temp(base)} C")
    handles, _ = ax.get_legend_handles_labels()
    handles += [Patch(facecolor="tab:blue", edgecolor="0.2", label="chosen"),
                Patch(facecolor="tab:cyan", edgecolor="0.2", label="BIC below baseline"),
                Patch(facecolor="0.8", hatch="//", edgecolor="0.2", label="BIC not below baseline")]
    ax.set_xticks(x, [f"{c.get('effect')}\n{c.get('target') or ''}" for c in candidates], fontsize=8)
    ax.set_xlabel("candidate effect / target")
    ax.set_ylabel("validation RMSE of the air residual (C)")
    tops = [v for v in [base] + [_val_rmse(c) for c in candidates] if v is not None]
    if tops:
        ax.set_ylim(0, 1.15 * max(tops))
    ax.set_title("Candidate effects: validation RMSE after calibration")
    ax.grid(axis="y", alpha=0.3)
    fig.legend(handles=handles, loc="outside lower center", ncols=2, fontsize=9, frameon=False)
    return _save(fig, path)


# ---------------------------------------------------------------------------------------------
# report.md


def _md_table(header, rows):
    def cell(v):
        return str(v).replace("|", "\\|").replace("\n", " ")
    lines = ["| " + " | ".join(cell(h) for h in header) + " |",
             "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(cell(v) for v in row) + " |" for row in rows]
    return "\n".join(lines)


def _md_before_after(report):
    rows = []
    for window in WINDOWS:
        b, a = _metrics(report, "before", window), _metrics(report, "after", window)
        rows.append([window, _period_text(report, window),
                     fmt_temp(b.get("mean"), True), fmt_temp(a.get("mean"), True),
                     fmt_temp(b.get("sd")), fmt_temp(a.get("sd")),
                     fmt_temp(b.get("rmse")), fmt_temp(a.get("rmse")),
                     fmt_sig(b.get("J")), fmt_sig(a.get("J")),
                     fmt_int(b.get("n")), fmt_int(a.get("n"))])
    return _md_table(["window", "period", "mean before (C)", "mean after (C)", "sd before (C)", "sd after (C)",
                      "RMSE before (C)", "RMSE after (C)", "J before (C²)", "J after (C²)", "n before", "n after"],
                     rows)


def _md_localization(report, labels=None):
    loc = report.get("localization") or {}
    if not loc:
        return ["No localisation in this report."]
    scores = loc.get("node_scores") or {}
    J_unforced = _num(loc.get("J_unforced"))
    best = {str(b) for b in (loc.get("best_nodes") or [])}
    rank = {str(k): i + 1 for i, k in enumerate(loc.get("ranked_nodes") or [])}
    rows = []
    for k in sorted(scores, key=_node_sort_key):
        J = _num(scores[k])
        ratio = f"{100 * J / J_unforced:.1f} %" if J is not None and J_unforced else NA
        row = [k] + ([labels.get(str(k), "")] if labels else []) + [
            fmt_sig(J) if J is not None else "n/a (simulation failed)", ratio,
            rank.get(str(k), ""), "yes" if str(k) in best else ""]
        rows.append(row)
    header = ["node"] + (["sub-model"] if labels else []) + ["J forced alone (C²)", "J / J unforced",
                                                             "rank", "in best_nodes"]
    search = loc.get("search") or {}
    best_list = loc.get("best_nodes")
    out = [f"- measured nodes: {loc.get('measured_nodes', NA)}; output (air) node: {loc.get('output_node', NA)}",
           f"- chromosome (nodes the search may force): {loc.get('chromosome_nodes', NA)}",
           f"- J unforced: {fmt_sig(J_unforced)} C²; J with best_nodes forced: {fmt_sig(loc.get('J_best'))} C²",
           f"- **best_nodes: {best_list if best_list is not None else NA}**"
           + (" (no forcing explains the residual: the fault is in the air node's own equation, or nowhere)"
              if best_list == [] else ""),
           f"- ranked nodes (most helpful first): {loc.get('ranked_nodes', NA)}"]
    if search:
        keys = ("population", "generations", "pc", "pm", "seed") if search.get("method") != "exhaustive" else ()
        counts = ", ".join(f"{k} {fmt_search(search[k])}" for k in keys + ("evaluations", "unique_evaluations")
                           if search.get(k) is not None)
        out.append(f"- search: {search.get('method', NA)}" + (f" ({counts})" if counts else "")
                   + (f", {fmt_sig(search.get('seconds'), 3)} s" if _num(search.get("seconds")) is not None else ""))
        extra = []
        if search.get("J_min") is not None:
            extra.append(f"lowest J found {fmt_sig(search.get('J_min'))} C²")
        if search.get("min_nodes") is not None:
            extra.append(f"forcing {search.get('min_nodes')}")
        if search.get("tolerance") is not None:
            extra.append(f"noise tolerance on J {fmt_sig(search.get('tolerance'))} C²")
        if extra:
            out.append("- " + "; ".join(extra))
    out += ["", "J with each node forced alone (the paper's Table 4):", "", _md_table(header, rows)]
    return out


def fmt_search(v):
    return f"{v:g}" if isinstance(v, float) else str(v)


def fmt_bic(x):
    v = _num(x)
    return NA if v is None else f"{v:.1f}"


def _md_candidates(report):
    candidates = report.get("candidates") or []
    if not candidates:
        return ["No candidate effect was tried."]
    effect = report.get("effect") or {}
    rows = []
    for c in candidates:
        bic, base = _num(c.get("bic")), _num(c.get("bic_baseline"))
        delta = f"{bic - base:+.1f}" if bic is not None and base is not None else NA
        rows.append([("**" if _is_chosen(c, effect) else "") + str(c.get("effect"))
                     + (" (chosen)**" if _is_chosen(c, effect) else ""),
                     c.get("target") if c.get("target") is not None else "",
                     fmt_parameters(c.get("effect"), c.get("parameters")) or "-",
                     fmt_temp((c.get("calibration") or {}).get("rmse")), fmt_temp(_val_rmse(c)),
                     fmt_temp((c.get("validation") or {}).get("mean"), True),
                     fmt_bic(bic), fmt_bic(base), delta])
    return [_md_table(["effect", "target", "parameters (value ± std)", "calibration RMSE (C)",
                       "validation RMSE (C)", "validation mean (C)", "BIC", "baseline BIC", "ΔBIC"], rows)]


def _md_sensitivity(report):
    sens = report.get("sensitivity") or {}
    rows = []
    for key, params in sens.items():
        for name, s in (params or {}).items():
            s = s or {}
            mu, sigma = _num(s.get("mu_star")), _num(s.get("sigma"))
            ratio = f"{sigma / mu:.2f}" if mu and sigma is not None else NA
            rows.append([key, name, fmt_sig(mu, 3), fmt_sig(sigma, 3), ratio])
    if not rows:
        return []
    return ["## Sensitivity of J to the parameters (Morris elementary effects)", "",
            "μ* is the mean absolute elementary effect of a parameter on J, σ their spread "
            "(σ/μ* near or above 1: non-linear or interacting).", "",
            _md_table(["effect@target", "parameter", "μ* (C²)", "σ (C²)", "σ/μ*"], rows), ""]


def _relative(path, out_dir):
    try:
        return Path(path).resolve().relative_to(Path(out_dir).resolve()).as_posix()
    except (ValueError, TypeError, OSError):
        return str(path)


def write_report(out_dir, report: dict, series: dict) -> list[Path]:
    """Write report.md and its PNG plots in out_dir; return the plot paths (also to be listed by the caller in report['artifacts']['plots'])."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    report = report or {}
    if "zones" in series:  # the plots below draw the first objective zone
        zone = next(iter(series["zones"].values()))
        series = {**series, **{key: zone[key] for key in ("measured", "before", "after", "air_node")}}
    labels = {str(k): str(v) for k, v in (series.get("node_labels") or {}).items()}
    plots, notes = {}, {}
    if series.get("times") is not None and len(series["times"]):
        plots["temperature"] = plot_temperature(out_dir / PLOTS["temperature"], report, series)
        plots["residuals"] = plot_residuals(out_dir / PLOTS["residuals"], report, series)
    else:
        notes["temperature"] = notes["residuals"] = "No simulated series: no time plots."
    loc = report.get("localization") or {}
    if loc.get("node_scores"):
        plots["node_scores"] = plot_node_scores(out_dir / PLOTS["node_scores"], report, labels)
    else:
        notes["node_scores"] = "No node scores in the localisation."
    search = loc.get("search") or {}
    if _convergence_points(series.get("convergence")):
        plots["convergence"] = plot_convergence(out_dir / PLOTS["convergence"], report, series)
    elif search.get("method") == "exhaustive":
        notes["convergence"] = (f"The search was exhaustive ({search.get('evaluations', NA)} chromosomes, every one "
                                "scored): there is no convergence curve.")
    else:
        notes["convergence"] = "No convergence history was recorded for this search."
    if report.get("candidates"):
        plots["candidates"] = plot_candidates(out_dir / PLOTS["candidates"], report)
    else:
        notes["candidates"] = "No candidate effect was tried: no candidates plot."

    def figure(key, caption):
        if key in plots:
            return [f"![{caption}]({_relative(plots[key], out_dir)})", ""]
        return [f"*{notes.get(key, '')}*", ""]

    period = report.get("period") or {}
    md = ["# nodeforce diagnosis report", "",
          "From the residual of the indoor air, to the nodes whose forcing explains it, to a physical "
          "effect the model lacks, added and calibrated on the calibration window; the validation "
          "window was not seen by the calibration.", "",
          "## Result", "", *_bold_lines(effect_header(report, pm='±')), "", rationale(report), "",
          "## Period", "",
          f"- calibration: {_period_text(report, 'calibration')}"
          + (f" (residuals scored from {_time_text(period['calibration_scored_from'])}, after the burn-in)"
             if period.get("calibration_scored_from") else ""),
          f"- validation: {_period_text(report, 'validation')}"]
    if _num(report.get("noise_sigma")) is not None:
        md.append(f"- measurement noise of the air, estimated from its second differences: "
                  f"sigma = {fmt_sig(report['noise_sigma'], 2)} C")
    md += ["", "## Before and after", "",
           "Residual r = T_air measured - T_air simulated (a positive mean: the model is too cold); "
           "mean and standard deviation as in the paper's Table 5, with RMSE, J = Σ r² and n the "
           "number of measured steps.", "",
           _md_before_after(report), ""]
    md += figure("temperature", "Measured and simulated indoor air temperature, before and after")
    md += figure("residuals", "Air residual before and after, mean and sd per window")
    md += ["## Localisation", ""] + _md_localization(report, labels) + [""]
    md += figure("node_scores", "J with each node forced alone")
    md += figure("convergence", "Exhaustive search: best J per batch" if search.get("method") == "exhaustive"
                 else "GA convergence: best J against the generation")
    md += ["## Candidate effects", "",
           "Each candidate is calibrated on the calibration window and scored on both; BIC on the "
           "calibration window, against the baseline's (the model without an effect). The chosen "
           "effect has the best validation RMSE among those whose BIC beats the baseline's and whose "
           "validation error falls by more than the noise; none is chosen when no candidate does.", ""]
    md += _md_candidates(report) + [""]
    md += figure("candidates", "Validation RMSE per candidate against the baseline")
    md += _md_sensitivity(report)
    artifacts = {k: v for k, v in (report.get("artifacts") or {}).items() if k != "plots" and v}
    if artifacts:
        md += ["## Files", ""] + [f"- {k}: [{_relative(v, out_dir)}]({_relative(v, out_dir)})"
                                  for k, v in artifacts.items()] + [""]
    (out_dir / "report.md").write_text("\n".join(md), encoding="utf-8")
    return [plots[k] for k in PLOTS if k in plots]
