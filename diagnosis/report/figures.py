"""The report's figures (PNG): air temperature and residual per zone against time, the
localisation (J per node forced alone, search convergence), the candidates, and the residual
diagnostics (autocorrelation, strongest cross-correlation) before and after.

Drawn on matplotlib Figure objects with the Agg canvas, so writing a report changes no global
matplotlib state (no pyplot, no backend switch). Missing numbers are left out of the plots.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib import dates as mdates
from matplotlib import patheffects
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import Patch
from matplotlib.ticker import MaxNLocator

from . import content
from .content import WINDOWS, metrics
from .formats import fmt_sig, fmt_temp, num, utc_offset
from .tables import node_sort_key
from ..residuals import lag_text

FILES = {
    "temperature": "air_temperature.png",
    "residuals": "residuals.png",
    "residual_diagnostics": "residual_diagnostics.png",
    "node_scores": "node_scores.png",
    "convergence": "convergence.png",
    "candidates": "candidates.png",
}

COLOR = {"measured": "black", "before": "tab:red", "after": "tab:blue", "validation": "0.88"}


def _new_figure(width=10.0, height=4.8):
    fig = Figure(figsize=(width, height), layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def _save(fig, path):
    fig.savefig(path, dpi=110)
    return path


# ---------------------------------------------------------------------------------------------
# against time, one row per zone


def _local_times(times):
    """Naive wall-clock times (plotted as read on site) and the axis label naming the offset."""
    times = pd.DatetimeIndex(times)
    if times.tz is None:
        return times, "time"
    return times.tz_localize(None), f"time ({utc_offset(times[0])})"


def _local_instant(t, times):
    if t is None:
        return None
    t = pd.Timestamp(t)
    tz = pd.DatetimeIndex(times).tz
    if t.tzinfo is not None:
        t = t.tz_convert(tz).tz_localize(None) if tz is not None else t.tz_localize(None)
    return t


class TimeAxes:
    """The rows of a plot against time, one per zone, sharing the time axis, the shading of the
    burn-in (not scored) and of the validation window, and the series of each zone."""

    def __init__(self, report, series):
        self.times, self.xlabel = _local_times(series["times"])
        self.start = _local_instant(series.get("validation_start"), series["times"])
        scored = _local_instant(series.get("scored_from"), series["times"])
        self.scored_from = scored if scored is not None and scored > self.times[0] else None
        available = series.get("zones") or {}
        self.zones = [z for z in content.zones(report, series) if z in available]
        self.series = {z: available[z] for z in self.zones}
        self.unchanged = content.is_none_effect(report.get("effect"))
        self.fig = _new_figure(10.0, 1.6 + 2.7 * len(self.zones))
        self.axes = self.fig.subplots(len(self.zones), 1, sharex=True, squeeze=False)[:, 0]
        for i, ax in enumerate(self.axes):
            if self.scored_from is not None:
                ax.axvspan(self.times[0], self.scored_from, facecolor="none", edgecolor="0.7", hatch="//", lw=0,
                           zorder=0, label="burn-in (not scored)" if i == 0 else None)
            if self.start is not None and self.start < self.times[-1]:
                ax.axvspan(self.start, self.times[-1], color=COLOR["validation"], zorder=0,
                           label="validation window" if i == 0 else None)

    def array(self, zone, key):
        a = self.series[zone].get(key)
        if a is None:
            return None
        a = np.asarray(a, dtype=float).reshape(-1)
        return a if len(a) == len(self.times) else None

    def masks(self):
        """The scored steps of each window (the burn-in is in neither)."""
        val = np.zeros(len(self.times), bool) if self.start is None else np.asarray(self.times >= self.start)
        scored = np.ones(len(self.times), bool) if self.scored_from is None else np.asarray(self.times >= self.scored_from)
        return {"calibration": ~val & scored, "validation": val}

    def title(self, zone):
        node = self.series[zone].get("air_node")
        return zone + (f" (air node {node})" if node is not None else "")

    def finish(self, path, ylabel, title, legend_columns):
        t0, end = self.scored_from or self.times[0], self.times[-1]
        style = dict(transform=self.axes[0].get_xaxis_transform(), va="top", fontsize=9, color="0.35", ha="center",
                     bbox=dict(facecolor="white", edgecolor="none", alpha=0.7, pad=1))
        if self.start is not None:
            if t0 < self.start:
                self.axes[0].text(t0 + (self.start - t0) / 2, 0.98, "calibration", **style)
            if self.start < end:
                self.axes[0].text(self.start + (end - self.start) / 2, 0.98, "validation", **style)
        for ax in self.axes:
            ax.set_ylabel(ylabel)
            ax.grid(alpha=0.3)
            ax.margins(x=0)
        locator = mdates.AutoDateLocator()
        self.axes[-1].xaxis.set_major_locator(locator)
        self.axes[-1].xaxis.set_major_formatter(mdates.ConciseDateFormatter(locator))
        self.axes[-1].set_xlabel(self.xlabel)
        self.fig.suptitle(title)
        handles, labels = self.axes[0].get_legend_handles_labels()
        # as many columns as the longest label lets fit across the figure (9 pt: about 14
        # characters an inch, with room for the line sample), so none is cut at the edge
        fit = int(self.fig.get_figwidth() * 14 // (max(map(len, labels), default=1) + 6))
        self.fig.legend(handles, labels, loc="outside lower center", ncols=max(1, min(legend_columns, fit)),
                        fontsize=9, frameon=False)
        return _save(self.fig, path)


def plot_temperature(path, report, series):
    """Measured and simulated air temperature per zone, before and after, validation shaded."""
    plot = TimeAxes(report, series)
    for i, (zone, ax) in enumerate(zip(plot.zones, plot.axes)):
        measured, before, after = (plot.array(zone, k) for k in ("measured", "before", "after"))
        if before is not None:
            ax.plot(plot.times, before, color=COLOR["before"], lw=1.4,
                    label=("simulated (no effect added)" if plot.unchanged else "simulated before") if i == 0 else None)
        if after is not None and not plot.unchanged:
            ax.plot(plot.times, after, color=COLOR["after"], lw=1.4,
                    label=f"simulated after ({content.effect_label(report)})" if i == 0 else None)
        if measured is not None:
            ax.plot(plot.times, measured, color=COLOR["measured"], lw=0, marker=".", ms=2.5,
                    label="measured" if i == 0 else None)
        ax.set_title(plot.title(zone), fontsize=10, loc="left")
    return plot.finish(path, "air temperature (C)", "Indoor air temperature: measured and simulated", 4)


def plot_residuals(path, report, series):
    """Residual per zone before and after over time; mean per window (report.json's) as a
    dashed segment and with the sd in the corner (the paper's Table 5)."""
    plot = TimeAxes(report, series)
    masks = plot.masks()
    outline = [patheffects.withStroke(linewidth=4, foreground="white")]
    states = ["before"] + ([] if plot.unchanged else ["after"])
    for i, (zone, ax) in enumerate(zip(plot.zones, plot.axes)):
        measured = plot.array(zone, "measured")
        ax.axhline(0, color="0.4", lw=0.8)
        lines = []
        for state in states:
            simulated = plot.array(zone, state)
            if simulated is None or measured is None:
                continue
            name = "no effect added" if plot.unchanged else state
            ax.plot(plot.times, measured - simulated, color=COLOR[state], lw=0.9, alpha=0.85,
                    label=name if i == 0 else None)
            stats = []
            for window in WINDOWS:
                m = metrics(report, state, window, zone)
                mean = num(m.get("mean"))
                if mean is not None and masks[window].any():
                    t_w = plot.times[masks[window]]
                    ax.plot([t_w[0], t_w[-1]], [mean, mean], color=COLOR[state], lw=2, ls="--", zorder=5,
                            path_effects=outline)
                stats.append(f"{window[:3]}. {fmt_temp(mean, True)} ± {fmt_temp(m.get('sd'))}")
            lines.append(f"{name}: " + ", ".join(stats))
        ax.text(0.01, 0.03, "\n".join(lines) + "  (mean ± sd, C)", transform=ax.transAxes, fontsize=8, va="bottom",
                bbox=dict(facecolor="white", edgecolor="0.8", alpha=0.85, pad=2))
        ax.set_title(plot.title(zone), fontsize=10, loc="left")
    plot.axes[0].plot([], [], color="0.3", ls="--", lw=2, label="mean over the window (scored steps)")
    return plot.finish(path, "measured - simulated (C)", "Indoor air residual before and after the correction", 4)


# ---------------------------------------------------------------------------------------------
# localisation and candidates


def plot_node_scores(path, report):
    """J with each node forced alone, J unforced as a line, best_nodes highlighted (Table 4)."""
    loc = report.get("localization") or {}
    scores = loc.get("node_scores") or {}
    nodes = sorted(scores, key=node_sort_key)
    best = {str(b) for b in (loc.get("best_nodes") or [])}
    values = [num(scores[k]) for k in nodes]
    J_unforced = num(loc.get("J_unforced"))
    finite = [v for v in values if v is not None and v > 0]
    # linear shows best how much of J a forcing removes; log only when some forcing makes J explode
    if J_unforced:
        log = bool(finite) and max(finite) > 5 * J_unforced
    else:
        log = bool(finite) and max(finite) / min(finite) > 30
    named = bool(report.get("node_names"))
    fig = _new_figure(max(7.0, (0.7 if named else 0.45) * len(nodes) + 3), 5.2 if named else 4.8)
    ax = fig.add_subplot()
    x = np.arange(len(nodes))
    ax.bar(x, [v if v is not None else 0 for v in values], edgecolor="0.2", lw=0.5,
           color=["tab:orange" if k in best else "tab:gray" for k in nodes])
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
    J_best = num(loc.get("J_best"))
    if J_best is not None and best:
        ax.axhline(J_best, color="tab:orange", ls=":", lw=1.2,
                   label=f"J with best_nodes ({', '.join(sorted(best, key=node_sort_key))}) forced = {fmt_sig(J_best)} C²")
    handles, _ = ax.get_legend_handles_labels()
    if best:
        handles.append(Patch(facecolor="tab:orange", edgecolor="0.2", label="in best_nodes"))
    handles.append(Patch(facecolor="tab:gray", edgecolor="0.2", label="other node" if best else "node (best_nodes = [])"))
    if J_unforced and any(v is not None for v in values):
        handles.append(Patch(facecolor="none", edgecolor="none", label="above the bars: J as % of J unforced"))
    ticks = [f"{k}\n{content.node_name(report, k)}".strip() for k in nodes]
    ax.set_xticks(x, ticks, fontsize=8 if named else 9, rotation=90 if named else 0)
    ax.set_xlabel("node forced alone to its measurement")
    ax.set_ylabel("J = sum of squared air residuals (C²)" + (", log scale" if log else ""))
    if log:
        ax.set_yscale("log")
    ax.set_title("Localisation: J with each node forced alone")
    ax.grid(axis="y", alpha=0.3)
    fig.legend(handles=handles, loc="outside lower center", ncols=2, fontsize=9, frameon=False)
    return _save(fig, path)


def convergence_points(convergence):
    """[(generation, J)] with finite numbers only."""
    pts = []
    for item in convergence or []:
        g, J = num(item[0]), num(item[1])
        if g is not None and J is not None:
            pts.append((g, J))
    return pts


def plot_convergence(path, report, series):
    """Best J so far against the generation of the GA (or the batch, for an exhaustive search)."""
    pts = convergence_points(series.get("convergence"))
    loc = report.get("localization") or {}
    search = loc.get("search") or {}
    g, J = np.array([p[0] for p in pts]), np.array([p[1] for p in pts])
    fig = _new_figure(8.0, 4.5)
    ax = fig.add_subplot()
    ax.step(g, J, where="post", color="tab:blue", lw=1.6, marker="o", ms=3, label="best J so far")
    J_unforced = num(loc.get("J_unforced"))
    if J_unforced is not None:
        ax.axhline(J_unforced, color="black", ls="--", lw=1.2, label=f"J unforced = {fmt_sig(J_unforced)} C²")
    J_min = num(search.get("J_min"))
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


# the loop's verdict on a candidate, as drawn: its cross-validation test, and physics' objection
VERDICT_STYLES = {
    "passes": (dict(facecolor="tab:cyan"), "passes the cross-validation"),
    "refused": (dict(facecolor="lightcyan", hatch=".."), "passes, refused by physics (a suggestion)"),
    "fails": (dict(facecolor="0.8", hatch="//"), "does not pass"),
}


def verdict_key(verdict):
    if not verdict.get("passes"):
        return "fails"
    return "refused" if verdict.get("objection") else "passes"


PLOTTED_CANDIDATES = 24


def plot_candidates(path, report):
    """Validation RMSE of the candidates against the baseline's, coloured by the loop's verdict:
    every chosen one and the others of lowest cross-validated error, PLOTTED_CANDIDATES in all
    (a round calibrates tens), one bar a row in the order they were tried, each named by its
    effect and target (and round, where there are several)."""
    tried = report.get("candidates") or []
    kept = sorted(tried, key=lambda c: (not content.is_chosen(report, c),
                                        num((c.get("cv") or {}).get("J")) if num((c.get("cv") or {}).get("J"))
                                        is not None else np.inf))[:PLOTTED_CANDIDATES]
    candidates = [c for c in tried if any(c is k for k in kept)]
    rounds = len({c.get("round") for c in tried}) > 1
    base = num(metrics(report, "before", "validation").get("rmse"))
    fig = _new_figure(10.0, 1.8 + 0.32 * len(candidates))
    ax = fig.add_subplot()
    y = np.arange(len(candidates))[::-1]
    used = set()
    for yi, c in zip(y, candidates):
        v = num(metrics(report, c, "validation").get("rmse"))
        if v is None:
            ax.text(0.01, yi, "failed", transform=ax.get_yaxis_transform(), va="center", fontsize=8, color="tab:red")
            continue
        key = verdict_key(content.verdict(report, c))
        style = dict(facecolor="tab:blue") if content.is_chosen(report, c) else VERDICT_STYLES[key][0]
        used.add("chosen" if content.is_chosen(report, c) else key)
        ax.barh(yi, v, height=0.7, edgecolor="0.2", lw=0.5, **style)
        cv = num((c.get("cv") or {}).get("rmse"))
        ax.annotate(fmt_temp(v) + (f" (CV {fmt_temp(cv)})" if cv is not None else ""), (v, yi), xytext=(3, 0),
                    textcoords="offset points", va="center", fontsize=8)
    if base is not None:
        ax.axvline(base, color=COLOR["before"], ls="--", lw=1.2, label=f"baseline (no effect) = {fmt_temp(base)} C")
    ref = content.reference(report)
    ref_rmse = num(ref[1].get("validation")) if ref else None
    if ref_rmse is not None:
        ax.axvline(ref_rmse, color="tab:green", ls=":", lw=1.2, label=f"{ref[0]} = {fmt_temp(ref_rmse)} C")
    handles, _ = ax.get_legend_handles_labels()
    if "chosen" in used:
        handles.append(Patch(facecolor="tab:blue", edgecolor="0.2", label="chosen"))
    handles += [Patch(edgecolor="0.2", label=label, **style) for key, (style, label) in VERDICT_STYLES.items()
                if key in used]
    ax.set_yticks(y, [f"{c.get('effect')} / {c.get('target') or ''}" + (f", round {c.get('round')}" if rounds else "")
                      for c in candidates], fontsize=8)
    ax.set_ylim(-0.7, len(candidates) - 0.3)
    ax.set_xlabel("validation RMSE of the air residual (C)")
    tops = [v for v in [base, ref_rmse] + [num(metrics(report, c, "validation").get("rmse")) for c in candidates]
            if v is not None]
    if tops:
        ax.set_xlim(0, 1.3 * max(tops))  # room for the values written after the bars
    ax.set_title("Candidate effects: validation RMSE after calibration"
                 + (f"\n(the {len(candidates)} of {len(tried)} of lowest cross-validated error)"
                    if len(candidates) < len(tried) else ""))
    ax.grid(axis="x", alpha=0.3)
    fig.legend(handles=handles, loc="outside lower center", ncols=2, fontsize=9, frameon=False)
    return _save(fig, path)


# ---------------------------------------------------------------------------------------------
# residual diagnostics


def plot_residual_diagnostics(path, report):
    """Left: the residual's autocorrelation before and after, with the 95 % band of white noise.
    Right: the strongest prewhitened cross-correlation of each, with its Bonferroni bound."""
    diags = {state: d for state, d in (report.get("residuals") or {}).items() if d and d.get("acf")}
    fig = _new_figure(11.0, 4.6)
    ax_acf, ax_ccf = fig.subplots(1, 2)
    for state, d in diags.items():
        lags = np.arange(len(d["acf"])) * d["step_hours"]
        ax_acf.plot(lags, d["acf"], color=COLOR[state], lw=1.4, label=f"{state} (n = {d['n']})")
        ax_acf.axhspan(-d["acf_bound"], d["acf_bound"], color=COLOR[state], alpha=0.12, lw=0)
        s = d.get("strongest")
        if s:
            lags = np.arange(len(s["ccf"])) * d["step_hours"]
            ax_ccf.plot(lags, s["ccf"], color=COLOR[state], lw=1.2, ls="--" if state == "after" else "-",
                        label=f"{state}: {s['input']}")
            for sign in (-1, 1):
                ax_ccf.axhline(sign * s["bound"], color=COLOR[state], ls=":", lw=1)
            ax_ccf.annotate(f"{s['input']}, {lag_text(s['lag_hours'])}", (s["lag_hours"], s["correlation"]),
                            xytext=(6, 6 if s["correlation"] > 0 else -12), textcoords="offset points",
                            fontsize=8, color=COLOR[state])
    ax_acf.axhline(0, color="0.4", lw=0.8)
    ax_acf.set(xlabel="lag (h)", ylabel="autocorrelation of the residual",
               title="Autocorrelation (shaded: 95 % band of white noise)")
    ax_ccf.axhline(0, color="0.4", lw=0.8)
    ax_ccf.set(xlabel="residual behind the input by (h)", ylabel="prewhitened cross-correlation",
               title="Strongest input (dotted: significance bound)")
    for ax in (ax_acf, ax_ccf):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=9, framealpha=0.9)
    fig.suptitle("Residual diagnostics on the validation window")
    return _save(fig, path)


def draw(out_dir, report, series):
    """Every figure the report has data for: ({key: path}, {key: why a figure is absent})."""
    plots, notes = {}, {}
    if series.get("times") is not None and len(series["times"]) and series.get("zones"):
        plots["temperature"] = plot_temperature(out_dir / FILES["temperature"], report, series)
        plots["residuals"] = plot_residuals(out_dir / FILES["residuals"], report, series)
    else:
        notes["temperature"] = notes["residuals"] = "No simulated series: no time plots."
    if any(d and d.get("acf") for d in (report.get("residuals") or {}).values()):
        plots["residual_diagnostics"] = plot_residual_diagnostics(out_dir / FILES["residual_diagnostics"], report)
    else:
        notes["residual_diagnostics"] = "No residual diagnostics in this report."
    loc = report.get("localization") or {}
    if loc.get("node_scores"):
        plots["node_scores"] = plot_node_scores(out_dir / FILES["node_scores"], report)
    else:
        notes["node_scores"] = "No node scores in the localisation."
    search = loc.get("search") or {}
    if convergence_points(series.get("convergence")):
        plots["convergence"] = plot_convergence(out_dir / FILES["convergence"], report, series)
    elif search.get("method") == "exhaustive":
        notes["convergence"] = (f"The search was exhaustive ({search.get('evaluations', 'n/a')} chromosomes, every "
                                "one scored): there is no convergence curve.")
    else:
        notes["convergence"] = "No convergence history was recorded for this search."
    if report.get("candidates"):
        plots["candidates"] = plot_candidates(out_dir / FILES["candidates"], report)
    else:
        notes["candidates"] = "No candidate effect was tried: no candidates plot."
    return {k: plots[k] for k in FILES if k in plots}, notes


def plot_comparison(path, result, series):
    """`nodeforce compare`: per objective zone, the measured air and each model's (top), and
    each model's residual (below), the burn-in hatched; each model labelled by its file and its
    RMSE over the scored steps."""
    times, xlabel = _local_times(series["times"])
    scored = _local_instant(series.get("scored_from"), series["times"])
    zones = result["objective"]
    fig = _new_figure(10.0, 1.6 + 4.4 * len(zones))
    axes = fig.subplots(2 * len(zones), 1, sharex=True, squeeze=False)[:, 0]
    colors = ["tab:red", "tab:blue", "tab:green", "tab:purple", "tab:orange", "tab:brown"]
    for j, zone in enumerate(zones):
        top, bottom = axes[2 * j], axes[2 * j + 1]
        for ax in (top, bottom):
            if scored is not None and scored > times[0]:
                ax.axvspan(times[0], scored, facecolor="none", edgecolor="0.7", hatch="//", lw=0, zorder=0,
                           label="burn-in (not scored)" if ax is axes[0] else None)
            ax.grid(alpha=0.3)
            ax.margins(x=0)
        measured = series["measured"][:, j]
        for k, (model, run) in enumerate(zip(result["models"], series["runs"])):
            label = f"{Path(model['building']).name} (RMSE {fmt_temp(model['metrics']['zones'][zone]['rmse'])} C)"
            top.plot(times, run[:, j], color=colors[k % len(colors)], lw=1.3, label=label if j == 0 else None)
            bottom.plot(times, measured - run[:, j], color=colors[k % len(colors)], lw=1.0)
        top.plot(times, measured, color=COLOR["measured"], lw=0, marker=".", ms=2.0, label="measured" if j == 0 else None)
        bottom.axhline(0.0, color="0.3", lw=0.8)
        top.set_title(zone, fontsize=10, loc="left")
        top.set_ylabel("air temperature (C)")
        bottom.set_ylabel("measured - simulated (C)")
    locator = mdates.AutoDateLocator()
    axes[-1].xaxis.set_major_locator(locator)
    axes[-1].xaxis.set_major_formatter(mdates.ConciseDateFormatter(locator))
    axes[-1].set_xlabel(xlabel)
    fig.suptitle("Building files on a record none was fitted on")
    fig.legend(loc="outside lower center", ncols=2, fontsize=9, frameon=False)
    return _save(fig, path)
