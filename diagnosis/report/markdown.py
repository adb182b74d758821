"""report.md: the diagnosis told in order (the first screen, result, decision, period, before and after, residual
diagnostics, localisation, candidates, sensitivity, files), with the tables and figures."""
from __future__ import annotations

from pathlib import Path

from . import content, summary, tables
from ..phases import WORSE
from .formats import NA, fmt_search, fmt_sig, num, time_text


def _relative(path, out_dir):
    try:
        return Path(path).resolve().relative_to(Path(out_dir).resolve()).as_posix()
    except (ValueError, TypeError, OSError):
        return str(path)


def _bold_label(line):
    """'**Fault:** in floor: ...' of 'Fault: in floor: ...'."""
    label, _, rest = line.partition(": ")
    return f"**{label}:** {rest}"


def decision_lines(report):
    """The loop's decision and its reason, the candidates physics refused (grouped by reason, each
    reason said once), and the margins it applied, as it recorded them."""
    d = content.decision(report)
    if not d:
        return ["*The loop recorded no decision in this report.*"]
    lines = [summary.chosen_sentence(report), ""]
    refused = summary.refusals(report)
    lines += refused + ([""] if refused else [])
    for number, r in enumerate(d.get("rounds") or [d], start=1):
        cost = r.get("cost") or {}
        which = (f"round {number}: cross-validated J of the model it starts from" if not r.get("replaces") else
                 f"{r['replaces']} chosen again, the other effects refitted together with each candidate: "
                 "cross-validated J of the model without it, the others refitted without it")
        lines.append(f"- {which} {fmt_sig(r.get('cv_J_before'))} C² "
                     f"over {r.get('blocks', NA)} days left out in turn; a candidate must lower it by more than the "
                     f"sensor noise and the file's numerical error could ({fmt_sig(r.get('noise_margin'))} C²) and by more than "
                     f"{fmt_sig(r.get('standard_errors'), 3)} standard error of its fall from day to day, on more "
                     f"days than its best (the fall needed, per candidate, in the candidates table); {cost.get('candidates', NA)} candidates, "
                     f"{cost.get('simulations', NA)} simulations, {cost.get('seconds', NA)} s; "
                     f"chosen: {r.get('chosen') or ('the start' if (r.get('start') or {}).get('chosen') else 'none')}"
                     + (f"; removed: {r['removed']}" if r.get("removed") else "") + start_clause(r.get("start")))
    lines.append(f"- chosen: {d.get('chosen') or 'none'}")
    return lines


def start_clause(start):
    """What a round's test of the start (report.json's round `start`) found: its cross-validated
    J, and on each record, fitted to the round's model on the calibration window, each mode's
    amplitude at the first measurement with its sd and its prior's, and its share of the
    window's J; "" where the start was no candidate."""
    if not start:
        return ""
    found = "; ".join(
        f"{r['record']}: " + ", ".join(f"its {tau:.3g}-day mode {a:+.3g} ± {sd:.2g} K (prior sd {prior:.2g} K)"
                                       for tau, a, sd, prior in zip(r["tau_days"], r["amplitude"], r["sd"],
                                                                    r["prior_sd"]))
        + f", {r['share_of_J']:.0%} of the window's J" for r in start.get("records", ()))
    verdict = ("chosen" if start["chosen"] else "not told from the best admissible effect" if start.get("within")
               else "passes, told from the best admissible effect" if start["passes"] else "does not pass")
    return (f"; the start as a candidate: cross-validated J {fmt_sig(start['cv_J'])} C², {verdict}"
            + (f" ({found})" if found else ""))


def localization_lines(report):
    loc = report.get("localization") or {}
    if not loc:
        return ["No localisation in this report."]
    best = loc.get("best_nodes")
    outputs = loc.get("output_nodes", loc.get("output_node", NA))
    out = [f"- measured nodes: {loc.get('measured_nodes', NA)}; output (air) nodes: {outputs}",
           f"- chromosome (nodes the search may force): {loc.get('chromosome_nodes', NA)}",
           f"- J unforced: {fmt_sig(loc.get('J_unforced'))} C²; J with best_nodes forced: {fmt_sig(loc.get('J_best'))} C²",
           f"- **best_nodes: {best if best is not None else NA}**"
           + (f": {', '.join(content.node_name(report, b) for b in best)}"
              if best and report.get("node_names") else ""),
           *([f"- {loc['finding']}"] if loc.get("finding") else []),
           f"- ranked nodes (lowest J first): {loc.get('ranked_nodes', NA)}"
           + (f"; the noise cannot separate {', '.join(map(str, loc['tied_nodes']))}" if loc.get("tied_nodes") else ""),
           *(["- evidence per component (share of J above the noise its forcing removes): " + ", ".join(
               f"{e['component']} {e['share']:.0%}" for e in loc["components"])] if loc.get("components") else [])]
    search = loc.get("search") or {}
    if search:
        keys = ("population", "generations", "pc", "pm", "seed") if search.get("method") != "exhaustive" else ()
        counts = ", ".join(f"{k} {fmt_search(search[k])}" for k in keys + ("evaluations", "unique_evaluations")
                           if search.get(k) is not None)
        out.append(f"- search: {search.get('method', NA)}" + (f" ({counts})" if counts else "")
                   + (f", {fmt_sig(search.get('seconds'), 3)} s" if num(search.get("seconds")) is not None else ""))
        extra = [text for key, text in (("J_min", f"lowest J found {fmt_sig(search.get('J_min'))} C²"),
                                        ("min_nodes", f"forcing {search.get('min_nodes')}"),
                                        ("tolerance", f"noise tolerance on J {fmt_sig(search.get('tolerance'))} C²"))
                 if search.get(key) is not None]
        if extra:
            out.append("- " + "; ".join(extra))
    return out + ["", "J with each node forced alone (the paper's Table 4):", "", tables.node_scores(report)]


def residual_lines(report):
    diags = report.get("residuals") or {}
    lines = [f"- {state}: {d.get('sentence', NA)}" for state, d in diags.items() if d]
    if not lines:
        return ["No residual diagnostics in this report."]
    return ["On the validation window, the residual of the objective: Ljung-Box test of whiteness, "
            "cross-correlation with every input after prewhitening (a significant one exceeds a "
            "Bonferroni bound over all lags and inputs), and a daily profile beyond the inputs "
            "(GLSAR F test). Computed on the longest run of consecutive measured steps; nothing is "
            "filled in.", ""] + lines + ["", tables.residual_diagnostics(report)]


def energyplus_lines(report):
    """The corrections written back into the EnergyPlus model (model_after.idf): each object
    changed or added, old and new values, and what no EnergyPlus object holds."""
    ep = report.get("energyplus")
    if not ep:
        return []
    lines = ["## The EnergyPlus model", "", f"The corrections written into {Path(ep['idf_after']).name}:", ""]
    for c in ep["changes"]:
        if c["field"] == "(new object)":
            fields = ", ".join(f"{k} {v:.6g}" if isinstance(v, float) else f"{k} {v}" for k, v in c["new"].items())
            lines.append(f"- new {c['object']} {c['name']}: {fields}")
        else:
            new = f"{c['new']:.6g}" if isinstance(c["new"], float) else c["new"]
            lines.append(f"- {c['object']} {c['name']}, {c['field']}: {c['old']} -> {new}")
    lines += [f"- not written: {line}" for line in ep["not_written"]]
    if not ep["changes"] and not ep["not_written"]:
        lines.append("- nothing: no effect was added")
    return lines + [""]


def write_markdown(out_dir, report, plots, notes):
    """Write out_dir/report.md; `plots` {key: path} and `notes` {key: why absent} of the figures."""
    def figure(key, caption):
        if key in plots:
            return [f"![{caption}]({_relative(plots[key], out_dir)})", ""]
        return [f"*{notes.get(key, '')}*", ""]

    search = (report.get("localization") or {}).get("search") or {}
    period = report.get("period") or {}
    ref = tables.reference_text(report)
    first_record = (f" of the first record ({report['records'][0]['name']}: the plots show it)"
                    if report.get("records") else "")
    md = ["# nodeforce diagnosis report", "", *[_bold_label(line) + "  " for line in summary.first_screen(report, pm="±")],
          "", "From the residual of the indoor air, to the nodes whose forcing explains it, to a physical "
          "effect the model lacks, added and calibrated on the calibration window and chosen by "
          "cross-validation over its days; the validation window played no part in any choice.", "",
          "## Result", "", *[f"**{line.strip()}**  " for line in tables.effect_header(report, pm="±").splitlines()],
          "", *[f"{line}  " for line in tables.hlc_lines(report, pm="±")], "",
          *([f"Modelling assumptions: {' '.join(report['assumptions'])}", ""] if report.get("assumptions") else []),
          "## Decision", "", *decision_lines(report), "",
          "## Period", "",
          f"- objective zones: {', '.join(content.zones(report)) or NA}",
          f"- calibration{first_record}: {content.period_text(report, 'calibration')}{content.scored_from_note(report)}",
          *([f"- cross-validation blocks (each left out of a fit in turn): {len(period['blocks'])} whole days"]
            if period.get("blocks") else []),
          f"- validation (before and after only, no part in any choice): {content.period_text(report, 'validation')}"]
    if report.get("records"):
        md += [f"- record {r['name']} ({r['measurements']}): calibration {content.period_text(r, 'calibration')}, "
               f"{len(r['period']['blocks'])} blocks; validation {content.period_text(r, 'validation')}"
               for r in report["records"]]
    md += [f"- later record {r['name']} ({r['measurements']}): {time_text(r['record'][0])} to "
           f"{time_text(r['record'][1])}, scored from {time_text(r['scored_from'])}: no fit, choice or "
           f"cross-validation read it; the building as written and as corrected were scored on it after the rounds, "
           f"as `nodeforce compare` scores them" for r in report.get("later") or ()]
    md += [f"- {report['noise'][key]}" for key in ("sentence", "numerical_sentence") if (report.get("noise") or {}).get(key)]
    md += ["", "## Before and after", "",
           "Residual r = T_air measured - T_air simulated (a positive mean: the model is too cold); "
           "mean and standard deviation as in the paper's Table 5, with RMSE, J = Σ r² and n the "
           "number of measured steps.", "", tables.before_after(report), ""]
    per_record = tables.records(report)
    if per_record:
        md += [f"The {len(report['records'])} records apart (the table above pools them; the plots show the "
               "first record):", "", per_record, ""]
    if ref:
        md += [f"For scale, the {ref}.", ""]
    by_phase = tables.phases(report)
    if by_phase:
        md += ["RMSE (C) of the objective's air in each phase of the record, over both windows (the "
               f"calibration fitted the first): ▲ marks a phase made worse than before by {WORSE:.0%} or more"
               + ("; the chosen candidates only, every candidate's in report.json" if len(
                   report["phases"][0]["rmse"]) > tables.PHASE_COLUMNS else "") + ".", "",
               by_phase, ""]
        by_zone = tables.phase_zones(report)
        if by_zone:
            md += ["Each zone in each phase, RMSE (C) before -> after:", "", by_zone, ""]
    md += figure("temperature", "Measured and simulated indoor air temperature, before and after")
    md += figure("residuals", "Air residual before and after, mean and sd per window")
    md += ["## Residual diagnostics", "", *residual_lines(report), ""]
    md += figure("residual_diagnostics", "Autocorrelation and strongest cross-correlation of the residual")
    md += ["## Localisation", ""]
    if report.get("records"):
        md += [f"The forcing search on the calibration windows of the {len(report['records'])} records together "
               "(a forcing applies to every record that measures its nodes; J is their sum), then on each "
               "record alone.", ""]
    md += [*localization_lines(report), ""]
    for r in report.get("records") or []:
        loc = r.get("localization") or {}
        if loc:
            md += [f"- {r['name']} alone: chromosome {loc.get('chromosome_nodes', NA)}; best_nodes "
                   f"{loc.get('best_nodes', NA)}. {loc.get('finding', '')}"]
    md += [""] if report.get("records") else []
    md += figure("node_scores", "J with each node forced alone")
    md += figure("convergence", "Exhaustive search: best J per batch" if search.get("method") == "exhaustive"
                 else "GA convergence: best J against the generation")
    md += ["## Candidate effects", ""]
    if report.get("candidates"):
        md += ["Each candidate is calibrated on the calibration window and scored on both; its verdict "
               "is the loop's (see Decision).", "", tables.candidates(report), ""]
        per_zone = tables.candidate_zones(report)
        md += [per_zone, ""] if per_zone else []
    else:
        md += ["No candidate effect was tried.", ""]
    md += figure("candidates", "Validation RMSE per candidate against the baseline")
    sensitivity = tables.sensitivity(report)
    if sensitivity:
        md += ["## Sensitivity of J to the parameters (Morris elementary effects)", "",
               "μ* is the mean absolute elementary effect of a parameter on J, σ their spread "
               "(σ/μ* near or above 1: non-linear or interacting).", "", sensitivity, ""]
    md += energyplus_lines(report)
    artifacts = {k: v for k, v in (report.get("artifacts") or {}).items() if k != "plots" and v}
    if artifacts:
        md += ["## Files", ""] + [f"- {k}: [{_relative(v, out_dir)}]({_relative(v, out_dir)})"
                                  for k, v in artifacts.items()] + [""]
    (Path(out_dir) / "report.md").write_text("\n".join(md), encoding="utf-8")
