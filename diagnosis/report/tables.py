"""The report's tables: the before/after table of the terminal, and report.md's tables (the
paper's Table 4 of the localisation, Table 5 of before and after per zone and window, the
candidates, the sensitivity, the residual diagnostics), each as a header and rows."""
from __future__ import annotations

from . import content
from .content import SCORED, STATES, metrics
from .formats import NA, fmt_derived, fmt_int, fmt_parameters, fmt_sig, fmt_temp, fmt_value_std, num, time_text
from ..phases import is_worse
from ..policy import Policy
from ..residuals import lag_text


def effect_header(report, pm="+-"):
    """The line naming the chosen effect, its target and parameters, or 'none: ...'."""
    effect = report.get("effect") or {}
    if content.is_none_effect(effect):
        return none_header(report)
    params = fmt_parameters(effect.get("effect"), effect.get("parameters"), pm)
    line = (f"Effect added: {content.effect_name(effect.get('effect'), effect.get('target'))}"
            + (f": {params}" if params else ""))
    # the HLC has its own line (`hlc_lines`)
    derived = {k: v for k, v in (effect.get("derived") or {}).items() if k != "heat_loss_coefficient"}
    return "\n".join([line] + [f"  the data determine {d}" for d in fmt_derived(derived, pm)])


def none_header(report):
    """The line of a diagnosis that added nothing: no candidate passed the choice, which reads the
    calibration window alone; and, where the validation error before is more than the error floor
    leaves (`Policy.at_noise` of its J on its n residuals at report.json's `noise.floor`, the
    sensors' noise and the file's numerical error), that the calibration days may not show a fault
    the validation does: a coupling to a ground near the floor's own temperature drifts the slow
    floor mode over weeks, and a few days' fall of J is within what the noise could make."""
    line = "Effect added: none: no candidate passes the choice on the calibration window"
    validation = (report.get("before") or {}).get("validation") or {}
    J, n, rmse = num(validation.get("J")), num(validation.get("n")), num(validation.get("rmse"))
    floor = num((report.get("noise") or {}).get("floor"))
    policy = Policy.of_json(report["policy"]) if report.get("policy") else Policy()
    if None in (J, n, rmse, floor) or not floor or policy.at_noise(J, n, floor):
        return line
    return (line + f"; the validation error, {rmse:.3f} C, is {rmse / floor:.2f} times the error floor of "
            f"{floor:.3f} C, beyond what it leaves: a fault these calibration days do not show may be there")


def hlc_lines(report, pm="+-"):
    """The heat loss coefficient as described and as corrected (W/K, docs/model.md section 8), and
    the sentence saying the data do not fix its split among effects, where they do not."""
    hlc = report.get("heat_loss_coefficient") or {}
    if num(hlc.get("before")) is None:
        return []
    line = f"Heat loss coefficient: {hlc['before']:.1f} W/K as described"
    if num(hlc.get("after")) is not None:
        line += f", {fmt_value_std(hlc['after'], hlc.get('after_sd'), pm)} W/K as corrected"
    return [line] + ([hlc["split"]] if hlc.get("split") else [])


def reference_text(report):
    """'IDEAS detailed model: RMSE 0.400 C (heat pulses), 0.600 C (free float)', '' without one."""
    ref = content.reference(report)
    if ref is None:
        return ""
    label, rmse = ref
    return f"{label}: RMSE " + ", ".join(f"{fmt_temp(v)} C ({key})" for key, v in rmse.items())


def _rows(report):
    """(label, zone) of the table rows: the objective, then each zone when there are several."""
    names = content.zones(report)
    return [("all zones" if len(names) > 1 else "", None)] + ([(z, z) for z in names] if len(names) > 1 else [])


def before_after_table(report: dict, header: bool = True) -> str:
    """The before/after table: rows calibration and validation windows (and each zone's, when the
    objective has several), columns RMSE, mean, sd of the air residual (C) and n, before and after;
    with `header`, a line naming the chosen effect, target and its parameters (value +- std, 'not
    identifiable' flagged), or 'none: ...' (`none_header`), and the heat loss
    coefficient (`nodeforce diagnose` prints the first screen instead, `terminal_summary`); the
    reference model's RMSE when the report has one."""
    cols = ("RMSE", "mean", "sd", "n")
    width = 8
    group = len(cols) * (width + 1) - 1
    rows = _rows(report)
    windows = _scored_windows(report)
    first = max([12] + [len(f"{w} {label}") for w in windows for label, _ in rows])
    lines = (effect_header(report, pm="+-").splitlines() if header else []) + [
        "Air residual r = measured - simulated (C)",
        f"{'':<{first}} | {'before':^{group}} | {'after':^{group}}",
        f"{'window':<{first}} | " + " ".join(f"{c:>{width}}" for c in cols)
        + " | " + " ".join(f"{c:>{width}}" for c in cols)]
    lines.append("-" * len(lines[-1]))
    for window in windows:
        for label, zone in rows:
            cells = []
            for state in STATES:
                m = metrics(report, state, window, zone)
                cells.append(" ".join(f"{v:>{width}}" for v in (
                    fmt_temp(m.get("rmse")), fmt_temp(m.get("mean"), signed=True), fmt_temp(m.get("sd")),
                    fmt_int(m.get("n")))))
            lines.append(f"{(window + ' ' + label).strip():<{first}} | {cells[0]} | {cells[1]}")
    lines += [f"{window}: {content.window_text(report, window)}" for window in windows]
    lines += (hlc_lines(report) if header else []) + [f"assumed: {a}" for a in report.get("assumptions") or ()]
    ref = reference_text(report)
    return "\n".join(lines + ([f"for scale, {ref}"] if ref else []))


# ---------------------------------------------------------------------------------------------
# report.md


def _scored_windows(report):
    """The windows the report has metrics for."""
    return list(SCORED)


def markdown(header, rows):
    """A markdown table."""
    def cell(v):
        return str(v).replace("|", "\\|").replace("\n", " ")
    lines = ["| " + " | ".join(cell(h) for h in header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    return "\n".join(lines + ["| " + " | ".join(cell(v) for v in row) + " |" for row in rows])


def before_after(report):
    """Table 5 of the paper per zone and window: mean and sd of the residual, with RMSE, J, n;
    the reference's RMSE beside the objective's where it has one for the window."""
    ref = content.reference(report)
    rmse_ref = ref[1] if ref else {}
    rows = []
    for label, zone in _rows(report):
        for window in _scored_windows(report):
            b, a = (metrics(report, state, window, zone) for state in STATES)
            rows.append([label or "objective", window, content.scored_period_text(report, window),
                         fmt_temp(b.get("mean"), True), fmt_temp(a.get("mean"), True),
                         fmt_temp(b.get("sd")), fmt_temp(a.get("sd")),
                         fmt_temp(b.get("rmse")), fmt_temp(a.get("rmse"))]
                        + ([fmt_temp(rmse_ref.get(window)) if zone is None else ""] if ref else [])
                        + [fmt_sig(b.get("J")), fmt_sig(a.get("J")), fmt_int(b.get("n")), fmt_int(a.get("n"))])
    return markdown(["zone", "window", "period", "mean before (C)", "mean after (C)", "sd before (C)",
                     "sd after (C)", "RMSE before (C)", "RMSE after (C)"]
                    + ([f"RMSE {ref[0]} (C)"] if ref else [])
                    + ["J before (C²)", "J after (C²)", "n before", "n after"], rows)


def node_sort_key(node):
    try:
        return (0, int(node), "")
    except (TypeError, ValueError):
        return (1, 0, str(node))


def node_scores(report):
    """Table 4 of the paper: J with each node forced alone, its share of J unforced, its rank."""
    loc = report.get("localization") or {}
    scores = loc.get("node_scores") or {}
    J_unforced = num(loc.get("J_unforced"))
    best = {str(b) for b in (loc.get("best_nodes") or [])}
    rank = {str(k): i + 1 for i, k in enumerate(loc.get("ranked_nodes") or [])}
    named = bool(report.get("node_names"))
    rows = []
    for k in sorted(scores, key=node_sort_key):
        J = num(scores[k])
        ratio = f"{100 * J / J_unforced:.1f} %" if J is not None and J_unforced else NA
        rows.append([k] + ([content.node_name(report, k)] if named else [])
                    + [fmt_sig(J) if J is not None else "n/a (simulation failed)", ratio,
                       rank.get(str(k), ""), "yes" if str(k) in best else ""])
    return markdown(["node"] + (["name"] if named else [])
                    + ["J forced alone (C²)", "J / J unforced", "rank", "in best_nodes"], rows)


def _yes_no(value):
    return NA if value is None else ("yes" if value else "no")


def candidates(report):
    """Each candidate: its parameters with their uncertainty, what the data determine, its
    errors, its BIC against the baseline's and the loop's verdict on it."""
    rows = []
    for c in report.get("candidates") or []:
        chosen = content.is_chosen(report, c)
        verdict = content.verdict(report, c)
        name = str(c.get("effect"))
        cv = c.get("cv") or {}
        rows.append([f"**{name} (chosen)**" if chosen else name,
                     c.get("target") if c.get("target") is not None else "",
                     fmt_parameters(c.get("effect"), c.get("parameters")) or "-",
                     "; ".join(fmt_derived(c.get("derived"))) or "-",
                     fmt_temp(metrics(report, c, "calibration").get("rmse")), fmt_temp(cv.get("rmse")),
                     fmt_temp(metrics(report, c, "validation").get("rmse")),
                     fmt_temp(metrics(report, c, "validation").get("mean"), True),
                     fmt_sig(verdict.get("cv_fall")), fmt_sig(verdict.get("needed")),
                     _yes_no(verdict.get("passes")), verdict.get("objection") or ""])
    return markdown(["effect", "target", "parameters (value ± std)", "the data determine",
                     "calibration RMSE (C)", "cross-validated RMSE (C)", "validation RMSE (C)",
                     "validation mean (C)", "cross-validated fall of J (C²)", "fall needed (C²)", "passes",
                     "objection"], rows)


def candidate_zones(report):
    """Validation RMSE of each candidate per zone ('' with a single zone)."""
    names = content.zones(report)
    if len(names) < 2 or not report.get("candidates"):
        return ""
    rows = [["before (no effect)"] + [fmt_temp(metrics(report, "before", "validation", z).get("rmse")) for z in names]]
    rows += [[content.candidate_key(c) + (" (chosen)" if content.is_chosen(report, c) else "")]
             + [fmt_temp(metrics(report, c, "validation", z).get("rmse")) for z in names]
             for c in report["candidates"]]
    return markdown(["validation RMSE (C)"] + names, rows)


def sensitivity(report):
    """Morris screening of J to each candidate's parameters ('' without one)."""
    rows = []
    for key, params in (report.get("sensitivity") or {}).items():
        for name, s in (params or {}).items():
            mu, sigma = num((s or {}).get("mu_star")), num((s or {}).get("sigma"))
            rows.append([key, name, fmt_sig(mu, 3), fmt_sig(sigma, 3), f"{sigma / mu:.2f}" if mu and sigma is not None else NA])
    return markdown(["effect@target", "parameter", "μ* (C²)", "σ (C²)", "σ/μ*"], rows) if rows else ""


def residual_diagnostics(report):
    """Before and after: the run analysed, Ljung-Box, the strongest input, the daily profile and
    the working days' excess over the rest days (n/a where the run holds one kind of day)."""
    rows = []
    for state in STATES:
        d = (report.get("residuals") or {}).get(state)
        if not d:
            continue
        lb, daily, follows = d.get("ljung_box") or {}, d.get("time_of_day") or {}, d.get("follows") or []
        run = d.get("run") or {}
        top = follows[0] if follows else None
        rows.append([state, f"{fmt_int(d.get('n'))} ({time_text(run.get('start'))} to {time_text(run.get('end'))})",
                     f"{fmt_sig(lb.get('statistic'), 3)} over {fmt_sig(lb.get('lag_hours'), 3)} h",
                     fmt_sig(lb.get("p_value"), 2), _yes_no(d.get("white")),
                     f"{top['input']}, {lag_text(top['lag_hours'])}, {top['correlation']:+.2f}" if top else "none",
                     (f"{fmt_temp(daily.get('amplitude'))} C at {fmt_sig(daily.get('peak_hour'), 3)} h, "
                      f"p = {fmt_sig(daily.get('p_value'), 2)}") if daily else NA,
                     (f"{fmt_temp(weekly.get('excess'))} C beyond a rest day, p = {fmt_sig(weekly.get('p_value'), 2)}"
                      if (weekly := d.get("working_days")) else NA)])
    return markdown(["residual", "steps analysed", "Ljung-Box Q", "p", "white",
                     "follows most (input, lag, prewhitened r)", "daily profile (amplitude, peak)",
                     "working days (mean excess)"], rows) if rows else ""


# Columns of the phases table beyond which only the chosen candidates' are shown.
PHASE_COLUMNS = 12


def phases(report):
    """RMSE (C) of each phase of the record: before, every candidate, after; a value made worse
    than before by the loop's margin (diagnosis.phases.WORSE) is marked ▲."""
    rows = report.get("phases") or []
    if not rows:
        return ""
    labels = list(rows[0]["rmse"])
    if len(labels) > PHASE_COLUMNS:
        # a whole house tries a hundred candidates: the table keeps the chosen ones (report.json has all)
        chosen = [f"{r['chosen']} (revisit of {r['replaces']})" if r.get("replaces") else
                  r["chosen"] if i == 0 else f"{r['chosen']} (round {i + 1})"
                  for i, r in enumerate((report.get("decision") or {}).get("rounds") or []) if r.get("chosen")]
        labels = [label for label in labels if label in ("before", "after") or label in chosen]

    def cell(row, label):
        value, before = num(row["rmse"].get(label)), num(row["rmse"].get("before"))
        return fmt_temp(value) + (" ▲" if label != "before" and is_worse(before, value) else "")
    return markdown(["phase", "from", "n"] + labels,
                    [[row["phase"], time_text(row["start"]), fmt_int(row["n"])] + [cell(row, label) for label in labels]
                     for row in rows])


def phase_zones(report):
    """RMSE (C) of each zone in each phase, before -> after, where the objective has several zones
    (a house's total can hide a room made worse: ▲); "" otherwise."""
    rows = [row for row in report.get("phases") or [] if row.get("zones") and row["n"]]
    if not rows:
        return ""
    zones = list(rows[0]["zones"])

    def cell(values):
        before, after = num(values.get("before")), num(values.get("after"))
        if before is None or after is None:
            return NA
        return f"{fmt_temp(before)} -> {fmt_temp(after)}" + (" ▲" if is_worse(before, after) else "")
    return markdown(["phase"] + zones, [[row["phase"]] + [cell(row["zones"][z]) for z in zones] for row in rows])


def records(report):
    """RMSE (C) before and after per record, window and zone, the objective's first, of a
    diagnosis of several records; "" for one."""
    rows = []
    for record in report.get("records") or []:
        for window in ("calibration", "validation"):
            b, a = record["before"][window], record["after"][window]
            rows.append([record["name"], window, "objective", fmt_temp(b["rmse"]), fmt_temp(a["rmse"]), fmt_int(b["n"])])
            rows += [[record["name"], window, zone, fmt_temp(z["rmse"]), fmt_temp(a["zones"][zone]["rmse"]),
                      fmt_int(z["n"])] for zone, z in b["zones"].items()] if len(b["zones"]) > 1 else []
    return markdown(["record", "window", "zone", "RMSE before (C)", "RMSE after (C)", "n"], rows) if rows else ""
