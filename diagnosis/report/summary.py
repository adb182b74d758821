"""The report's first screen, and the Decision's refusals said once per reason.

The first screen answers, in at most ten lines, what a modeller asks first: where the fault is
(with the forcing's evidence), what was added, what the data determine about it (the quantities
they fix; parameters they cannot fix are in the candidates table, never here), the error before
and after on the validation window, the heat loss coefficient as described and as corrected,
the error as written and as corrected on the later records no choice read, and what is left. It
reads report.json and decides nothing.
"""
from __future__ import annotations

import re

from . import content
from .content import metrics
from .formats import NA, fmt_derived, fmt_parameters, fmt_temp, num
from .tables import before_after_table, hlc_lines
from ...model.score import removed

#: The most lines the first screen may take (the title included in report.md).
FIRST_SCREEN_LINES = 10

# One clause of a physical objection (`diagnosis.policy.Policy.objection`): "NAME = VALUE [+- STD] UNIT
# is WHAT [LOW, HIGH]" or "... ends on WHAT"; anything else is kept whole as its own reason.
_CLAUSE = re.compile(r"^(?P<value>\w+ = \S+(?: \+- \S+)?(?: (?!is\b|ends\b)\S+)?) "
                     r"(?P<why>(?:is|ends on) .*?)(?: \[[^\]]*\])?$")


def _component(node_name):
    """'floor' of 'floor at 0.150 m'; a name without a depth ('living air') is kept whole."""
    return node_name.split(" at ", 1)[0]


def _forcing(report, nodes):
    """'node 16 (floor at 0.150 m)', 'nodes 70 (W9 at 0.000 m), 256 (corridor air)'."""
    named = [f"{b}" + (f" ({content.node_name(report, b)})" if content.node_name(report, b) else "") for b in nodes]
    return f"node{'s' if len(nodes) > 1 else ''} {', '.join(named)}"


def where_line(report):
    """Where the fault is: the components behind the best forcing and the share of J it removes."""
    loc = report.get("localization") or {}
    best = loc.get("best_nodes")
    search = loc.get("search") or {}
    J_unforced, J_noise = num(loc.get("J_unforced")), num(search.get("J_noise")) or 0.0
    of = "of J above the noise floor" if J_noise else "of J"
    if not loc:
        return "Fault: not searched for (no localisation in this report)"
    if best:
        names = [content.node_name(report, b) for b in best]
        components = list(dict.fromkeys(_component(n) for n in names if n)) or [f"node {b}" for b in best]
        share = (f" removes {removed(J_unforced, loc['J_best'], J_noise):.0%} {of}"
                 if J_unforced is not None and num(loc.get("J_best")) is not None else "")
        return f"Fault: in {', '.join(components)}: forcing {_forcing(report, best)}{share}"
    strongest, J_min = search.get("min_nodes"), num(search.get("J_min"))
    if strongest and J_unforced is not None and J_min is not None:
        return (f"Fault: not located: the best forcing, {_forcing(report, strongest)}, removes only "
                f"{removed(J_unforced, J_min, J_noise):.0%} {of}")
    return "Fault: not located: no forcing the sensors allow lowers J beyond the noise"


def added_effects(report):
    """The effects the loop added, in order, each with its parameters and what the data determine."""
    last = report.get("effect") or {}
    if content.is_none_effect(last):
        return []
    added = report.get("effects") or [last]
    rounds = []
    for i, e in enumerate(added):
        if i == len(added) - 1 and (e.get("effect"), e.get("target")) == (last.get("effect"), last.get("target")):
            rounds.append(last)
            continue
        tried = next((c for c in report.get("candidates") or [] if content.candidate_key(c) == content.candidate_key(e)
                      and bool(c.get("on_top_of")) == (i > 0)), {})
        rounds.append({**e, "derived": e.get("derived", tried.get("derived"))})
    return rounds


def determined(effect, pm):
    """What the data fix about an added effect: its identifiable parameters and the quantities its
    parameters trade off along (the heat loss coefficient has its own line), and those weighed with
    their physical priors (each with its prior, the posterior's sd); the parameters the data leave
    free are named as such, their values left to the candidates table."""
    parameters = effect.get("parameters") or {}
    weighed = {k: p for k, p in parameters.items() if p.get("prior")}
    fixed = {k: p for k, p in parameters.items() if p.get("identifiable") is not False and k not in weighed}
    free = [k for k in parameters if k not in fixed and k not in weighed]
    derived = {k: v for k, v in (effect.get("derived") or {}).items() if k != "heat_loss_coefficient"}
    said = [t for t in [fmt_parameters(effect.get("effect"), fixed, pm)] + fmt_derived(derived, pm) if t]
    text = ", ".join(said) if said else "nothing"
    if weighed:
        text += f", with {fmt_parameters(effect.get('effect'), weighed, pm)}"
    if free:
        text += (f" ({' and '.join(free)} {'each' if len(free) > 1 else 'alone'} not fixed by these data: "
                 "candidates table)")
    return text


def _change(before, after, signed=False):
    return f"{fmt_temp(before, signed)} -> {fmt_temp(after, signed)} C"


def error_line(report):
    """RMSE and mean error of the objective's air before and after, on the validation window."""
    b, a = (metrics(report, state, "validation") for state in content.STATES)
    return (f"Validation: RMSE {_change(b.get('rmse'), a.get('rmse'))}, mean error "
            f"{_change(b.get('mean'), a.get('mean'), signed=True)} (measured - simulated, "
            + (f"the validation windows of the {len(report['records'])} records together)" if report.get("records")
               else f"{content.period_text(report, 'validation')})"))


def hlc_line(report, pm):
    """`tables.hlc_lines`' first line, the split's sentence shortened to a clause; None without an HLC."""
    lines = hlc_lines(report, pm)
    if not lines:
        return None
    return lines[0] + (" (the data do not fix its split among the effects)" if len(lines) > 1 else "")


def left_line(report):
    """One sentence on what the corrected model still leaves: the structure of its residual on the
    validation window, and a phase the correction made worse."""
    after = (report.get("residuals") or {}).get("after") or {}
    sentence = after.get("sentence") or (content.decision(report).get("structure_left")) or ""
    worse = content.decision(report).get("worsened_phases") or []
    sentence = sentence[:1].lower() + sentence[1:].rstrip(".")
    text = f"Left: {sentence}" if sentence else "Left: no diagnostics of the residual in this report"
    if worse:
        text += "; made worse: " + ", ".join(
            f"{w['phase']} ({fmt_temp(w.get('before'))} -> {fmt_temp(w.get('after'))} C)" for w in worse)
    return text + "."


def later_line(report):
    """The RMSE of the objective's air on the later records, which no choice read, as written and
    as corrected; None without later records."""
    later = report.get("later") or []
    if len(later) == 1:
        r = later[0]
        return (f"Later record {r['name']}: RMSE {fmt_temp(r['before'].get('rmse'))} as written -> "
                f"{fmt_temp(r['after'].get('rmse'))} C as corrected (no choice read it)")
    if later:
        return ("Later records: " + ", ".join(f"{r['name']} {_change(r['before'].get('rmse'), r['after'].get('rmse'))}"
                                              for r in later)
                + " (RMSE as written -> as corrected; no choice read them)")
    return None


def first_screen(report, pm="+-"):
    """The first screen's lines (at most FIRST_SCREEN_LINES - 2: report.md adds its title and a
    blank line), each opening with its label ('Fault:', 'Added:', ...). What the data determine
    of several effects takes a line each, or one together where the screen would overflow."""
    effects = added_effects(report)
    if effects:
        added = ["Added: " + ", then ".join(content.effect_name(e.get("effect"), e.get("target"))
                                            for e in effects) + "."]
        said = [(f" for {e.get('effect')}" if len(effects) > 1 else "", determined(e, pm)) for e in effects]
        determine = [f"The data determine{of}: {text}." for of, text in said]
    else:
        added, determine = ["Added: nothing: " + chosen_sentence(report)], []
    rest = [error_line(report), hlc_line(report, pm), later_line(report)]
    rest = [line + "." for line in rest if line]
    if 2 + len(determine) + len(rest) + 1 > FIRST_SCREEN_LINES - 2:
        determine = ["The data determine: " + "; ".join(f"{of.strip()}: {text}" for of, text in said) + "."]
    return [where_line(report) + ".", *added, *determine, *rest, left_line(report)]


def terminal_summary(report):
    """What `nodeforce diagnose` and `demo` print: the first screen, then the before/after table
    of every scored window (`tables.before_after_table` without its header, which the first screen
    says)."""
    return "\n".join(first_screen(report)) + "\n\n" + before_after_table(report, header=False)


# ---------------------------------------------------------------------------------------------
# the Decision


def chosen_sentence(report):
    """The loop's reason: the refused candidates are not in it, `refusals` says them grouped."""
    return content.decision(report).get("reason") or NA


def _clauses(objection):
    """[(why, value)] of an objection: why it is refused ('is a negative gain (a heat sink)') and the
    value that shows it ('Q = -2.81 W'); a clause of another form is its own why."""
    out = []
    for clause in (c.strip() for c in str(objection).split("; ")):
        match = _CLAUSE.match(clause)
        out.append((match["why"], match["value"].removesuffix(" -")) if match else (clause, ""))
    return out


def refusals(report):
    """The candidates the data support but physics refused, one line per reason: 'N candidates ...
    each is a negative gain (a heat sink): a (Q = -2.81 W), b (...)'."""
    d = content.decision(report)
    suggestions = [s for r in (d.get("rounds") or [d]) for s in r.get("suggestions") or []]
    groups = {}
    for s in suggestions:
        clauses = _clauses(s.get("reason", ""))
        why = "; and ".join(w for w, _ in clauses)
        values = "; ".join(dict.fromkeys(v for _, v in clauses if v))
        groups.setdefault(why, []).append(s["candidate"] + (f" ({values})" if values else ""))
    lines = []
    for why, names in groups.items():
        n = len(names)
        said = f"{'each' if n > 1 else 'it'} {why}" if why.startswith(("is ", "ends on ")) else why
        lines.append(f"- {n} candidate{'s' if n > 1 else ''} the data support, not added: {said}: {', '.join(names)}")
    return lines
