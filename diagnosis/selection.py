"""The choice of one round (`decide`): which candidates pass, which physics refuses, the band of
those the data cannot tell from the best, and the one of it that claims least; the
cross-validation blocks of whole days it reads (`blocks`), the records a candidate harms
(`harmed`), and the decision in words. Why it is made so, step by step: docs/method.md,
"Choosing an effect"; the formulas: docs/model.md 6.6. Every threshold is the `Policy` passed in
(`diagnosis.policy`); the pass rule and the noise's yardstick are `model.score.Yardstick`'s.
"""
import math
from dataclasses import replace

import numpy as np

from nodeforce.diagnosis.result import Baseline, Decision, Verdict
from nodeforce.model.effects import EFFECTS
from nodeforce.model.errors import InputError
from nodeforce.model.integrate import steps_per_day
from nodeforce.model.score import fall


def blocks(n_steps, scored_from, dt, policy, source="measurements"):
    """(B, n_steps) bool: the steps of each block, whole days of the scored steps
    `scored_from`..n_steps-1 (the steps t_1..t_N of a window), the part day left at the end joined
    to the last block; at least the `policy`'s `min_blocks`."""
    day = steps_per_day(dt)
    n_blocks = (n_steps - scored_from) // day
    if n_blocks < policy.min_blocks:
        raise InputError(source, "time", f"a calibration window of {n_steps - scored_from} scored steps of {dt:g} s "
                                         f"leaves no calibration window of {policy.min_blocks} whole days after the burn-in "
                                         "for the cross-validation: give a longer calibration window")
    index = np.arange(n_steps)
    starts = scored_from + day * np.arange(n_blocks)
    ends = np.append(starts[1:], n_steps)
    return np.array([(index >= a) & (index < b) for a, b in zip(starts, ends)])


def on_block(shapes, record, block):
    """Per record, a bool array of its residuals' shape ((N_t, zones)): True on the steps of
    `block` ((N_t,) bool) of record `record`, False everywhere else; its complement is what a fit
    without the block reads."""
    return [np.broadcast_to(block[:, None] if i == record else np.zeros((shape[0], 1), bool), shape)
            for i, shape in enumerate(shapes)]


def block_J(residuals, masks):
    """J (C2) of residuals ((N_t, zones), NaN where not scored) on each block."""
    return np.array([np.nansum(np.square(residuals[m])) for m in masks])


def distance(a, b):
    """|r_a - r_b| (C) of two candidates' (`Fit`s) residuals their evidence (`Fit.evidence`) is
    made of: the air's left out and the other sensors' on the blocks; 0 where either lacks them."""
    ra, rb = a.residuals(), b.residuals()
    if ra is None or rb is None:
        return 0.0
    return float(np.linalg.norm(ra - rb))


def noise_difference(distance, sigma):
    """The standard deviation (C2) of the difference of two candidates' evidence that sensor noise
    of sd sigma (C) alone makes, given the `distance` |r_a - r_b| (C) of their residuals:
    J_a - J_b = sum (r_a - r_b)(r_a + r_b), and the noise e of a measurement enters r_a + r_b
    twice, so the difference moves by 2 sum (r_a - r_b) e, of sd 2 sigma |r_a - r_b|."""
    return float(2.0 * sigma * distance)


def parsimony(result, sigma, n, policy):
    """The fall of evidence (C2) a candidate must add over one that claims less (a physical effect
    against a shape, fewer parameters against more, the zone's own effect against one
    component's) to be preferred to it: what the sensors' noise alone could make of J over the
    residuals its evidence scores (`Policy.noise_change`), the yardstick that admits a
    candidate against the model (1.) and a forced node against fewer in the search. Its extra
    freedom fits what the file itself leaves (its coarser walls, a history it does not know) as
    well as the fault: a ground coupling against a constant gain, a daily profile against a
    window's sun, both on the air alone, differ by a hundredth of that, alike on every day, which
    neither the days' scatter nor a fixed pair's noise (`noise_difference`) would call small. One
    wall's factor bends that wall's dynamics, where the file's coarse nodes err, as the envelope's
    cannot: on the air alone it fits that error too. `n`: the air's scored residuals."""
    return policy.noise_change(sigma, n + result.sensors.n_weighted)


def harmed(base, scores, floor_sd, groups, policy):
    """The records a candidate harms: those on whose blocks its cross-validated J rises by more
    than the noise's tolerance of that record's J and one standard error of its per-block falls;
    [{"record", "cv_fall", "needed"}] (C2).

    Parameters
    ----------
    base, scores : per-block J (C2) of the model without and with the candidate
    floor_sd : the sd (C) of what a right model of the file leaves (`decide`'s: the sensors'
        noise and the file's own numerical error)
    groups : [{"record": name, "blocks": indices into base, "n": residuals they score}]
    policy : the `diagnosis.policy.Policy` whose yardstick judges
    """
    base, scores = np.asarray(base, dtype=float), np.asarray(scores, dtype=float)
    out = []
    for group in groups:
        rows = np.asarray(group["blocks"], dtype=int)
        judged = policy.yardstick.judge(base[rows], scores[rows],
                                        policy.least_fall(float(base[rows].sum()), floor_sd, group["n"]))
        if judged.reversed:
            out.append({"record": group["record"], "cv_fall": judged.fall, "needed": judged.needed})
    return out


def decide(results, baseline, policy):
    """The `Decision` of one round (module docstring), its steps in order: 1. which candidates
    pass, 2. which of them physics refuses (suggestions), 3. the band of those the data cannot
    tell from the best, 4. the one of the band that claims least; with each candidate's `Verdict`
    and the reason in words.

    Parameters
    ----------
    results : the candidates' `Fit`s
    baseline : what the choice reads besides them (`diagnosis.result.Baseline`): the model's
        per-block J, the noise, the residuals the blocks score, the records they come from
    policy : the `diagnosis.policy.Policy` whose thresholds judge
    """
    base = np.asarray(baseline.blocks_before, dtype=float)
    sigma, n, groups, air_at_noise = baseline.sigma, baseline.n, baseline.groups, baseline.air_at_noise
    floor_sd = sigma if baseline.floor_sd is None else baseline.floor_sd
    distances = baseline.distances
    margin = policy.least_fall(float(base.sum()), floor_sd, n)
    verdicts = {r.label: candidate_test(r, base, margin, floor_sd, groups, sigma, policy, air_at_noise)
                for r in results}
    passing = [r for r in results if verdicts[r.label].passes]  # 1.
    tight = [r for r in passing if not verdicts[r.label].objection]  # 2.
    loose = [r for r in passing if verdicts[r.label].objection and only_loose(r, verdicts[r.label], policy)]
    if distances is None and tight:
        weighed = tight + loose
        distances = {a.label: {b.label: distance(a, b) for b in weighed} for a in weighed}
    # loose values are weighed against the best tight candidate: where none passes, the line stands
    for r in loose if tight else []:
        verdicts[r.label] = weigh_loose(r, verdicts[r.label], min(tight, key=lambda t: t.evidence().sum()), base,
                                        sigma, distances, policy)
    admissible = [r for r in passing if not verdicts[r.label].objection]
    suggestions = [{"candidate": r.label, "reason": verdicts[r.label].objection, "cv_rmse": r.cv.rmse}
                   for r in passing if verdicts[r.label].objection]
    components = {r.target for r in results if r.physics["component"]}
    chosen, alike = None, []
    if admissible:
        near = band(admissible, base, sigma, floor_sd, n, distances, policy)  # 3.
        chosen = min(near, key=lambda r: (claim(r, policy), r.evidence().sum()))  # 4.
        alike = [r for r in near if r is not chosen]
    start = (None if baseline.start is None else
             start_test(baseline.start, base, margin, admissible, floor_sd, n, air_at_noise, policy))
    # the candidates physics refused are in `suggestions`; the report says them grouped by reason
    if start is not None and start["chosen"]:
        chosen, alike = None, []
        reason = _start_reason(start, base, len(results), len(passing))
    else:
        reason = _reason(chosen, alike, results, passing, base, n, verdicts, margin, components, air_at_noise, policy)
        if chosen is not None and start is not None and start["within"]:
            reason = reason[:-1] + _start_beside(start) + "."
    return Decision(chosen, reason, float(base.sum()), len(base), margin, policy.standard_errors, suggestions,
                    [r.label for r in alike], verdicts,
                    # what the steps read besides the candidates' fits: report.json can replay them
                    Baseline([float(b) for b in base], sigma, n, list(groups), floor_sd, distances or {},
                             air_at_noise, baseline.start).to_json(), start=start)


def start_test(start, base, margin, admissible, floor_sd, n, air_at_noise, policy):
    """The test of the start as a candidate: the records' slow modes' amplitudes at the first
    measurement, a start their short history leaves unknown (`model.start`), fitted on the days
    each block leaves as a candidate's parameters are; `start` its per-block J (C2), `base` the
    model's. It passes as a candidate passes (the noise's `margin`, the standard error of its
    fall, more days than one; never on the air at the noise). It is chosen where it passes and
    no admissible candidate does, or where the best of them (the lowest evidence) is within the
    band of it (`band`'s rule: the standard errors of the paired difference, at least the
    rounding, and the noise's tolerance `parsimony` gives a candidate that claims less): the
    start claims nothing about the building, so, as a physical effect before a shape, the
    no-fault explanation may win the tie (`Policy.prefer_start`); a fault is then added only
    where the data tell it from a start the history did not set. The comparison is on the air,
    the start's only evidence: it is fitted to the air, and what it would make of the other
    sensors no fit of it read. {"cv_J", "cv_fall", "cv_se", "needed", "other_days", "passes",
    "within": it passes and no admissible candidate is told from it, "chosen": within, and the
    policy prefers the start} (C2), and where a candidate was weighed against it, "against"
    (its label), "ahead" (how much lower its J on the air is) and "band" (what it needs to be
    told apart)."""
    start = np.asarray(start, dtype=float)
    judged = policy.yardstick.judge(base, start, margin)
    out = {"cv_J": float(start.sum()), "cv_fall": judged.fall, "cv_se": judged.se, "needed": judged.needed,
           "other_days": judged.other_days, "passes": bool(judged.beats) and not air_at_noise}
    within = out["passes"]
    if out["passes"] and admissible:
        best = min(admissible, key=lambda r: r.evidence().sum())
        ahead, se = fall(start, best.cv.blocks)
        width = max(policy.standard_errors * se, policy.rounding(float(base.sum())), parsimony(best, floor_sd, n, policy))
        within = ahead <= width
        out.update({"against": best.label, "ahead": ahead, "band": width})
    return {**out, "within": bool(within), "chosen": bool(within) and policy.prefer_start}


def revisited(decision, replaces, others, refitted, refit):
    """The `decision` of a choice made again once the rounds end (`diagnosis.loop.revisit`): of
    the effect `replaces` (its label), among candidates each fitted with the model's `others`
    (labels) refitted together with it, against the model without it, the others refitted
    together without it (`refit`, their `Fit`, whose cross-validated J per block the decision
    read); `refitted` ({label: {name: {"value", ...}}}) their values refitted with the one
    chosen, kept where it takes the place of `replaces`, or, where none is chosen, refitted
    without it: the effect is removed. The reason says which, in the effect's own numbers."""
    effect, target = replaces.split("@", 1)
    decision.replaces, decision.refit = replaces, refit
    decision.refitted = refitted if decision.changes_model or decision.chosen is None else {}
    if decision.changes_model:
        outcome = f"it takes the place of {effect} on {target}."
    elif decision.chosen is not None:
        outcome = "it stays."
    else:
        own = decision.verdicts[replaces]
        why = (f"it passes, but is refused: {own.objection}" if own.passes else
               f"its own cross-validated fall, {own.cv_fall:.3g} C2, is short of the {own.needed:.3g} C2 it needs"
               if own.cv_fall <= own.needed else
               f"its own cross-validated fall, {own.cv_fall:.3g} C2, comes from one day: the others gain "
               f"{own.other_days:.3g} C2")
        outcome = (f"{effect} on {target} is removed: {why}; the model keeps {', '.join(others)}, refitted "
                   f"without it (cross-validated J {refit.cv.J:.3g} C2, {refit.cv.rmse:.3f} C, against "
                   f"{refit.cv.J - own.cv_fall:.3g} C2 with it).")
    decision.reason = (f"{effect} on {target} chosen again, the other effects refitted together with each candidate "
                       f"and without it ({', '.join(others)}): {decision.reason[:-1]}; {outcome}")
    return decision


def candidate_test(result, base, margin, floor_sd, groups, sigma, policy, air_at_noise=False):
    """One candidate's `Verdict` (steps 1 and 2): its cross-validated fall of J (C2) and the fall's
    standard error, what it needs (the noise's `margin`, C2, and `standard_errors` of its
    scatter), what the days other than its best gain, its evidence, whether it passes (on the
    air unless `air_at_noise`, or on its own sensors), the records it harms and the objection of
    physics, None if none."""
    blocks = np.asarray(result.cv.blocks)
    # the other days than its best must gain too: one day alone is no evidence
    judged = policy.yardstick.judge(base, blocks, margin)
    down = judged.fall
    own = own_test(result.sensors.own, sigma, policy)
    by_own = bool(own is not None and own["passes"] and down > -margin)
    harms = harmed(base, blocks, floor_sd, groups, policy)
    said = policy.objection_of(result.effect, result.parameters, result.derived, result.physics)
    if harms:
        said = "; ".join(filter(None, [said, "it helps the records together but harms " + "; ".join(
            f"{h['record']} (its cross-validated J there rises by {-h['cv_fall']:.3g} C2, beyond the "
            f"{h['needed']:.3g} C2 the noise and the day-to-day scatter could make)" for h in harms)
            + ": a correction of the building must hold on every record of it"]))
    by_air = bool(judged.beats) and not air_at_noise
    return Verdict(down, judged.se, judged.needed, judged.other_days, float(result.evidence().sum()), by_air or by_own,
                   harms, said, own, by_own)


def only_loose(result, verdict, policy):
    """Whether all that refuses a passing candidate is that the data leave values of it loose
    (`Policy.loose_values`): no bound, no physical limit, no record it harms. A report that
    predates the weighing (its facts without "no_effect") replays with its loose values refused."""
    facts = result.physics
    return ("no_effect" in facts and not verdict.harms
            and bool(policy.loose_values(result.effect, result.parameters, result.derived, facts))
            and policy.objection_of(result.effect, result.parameters, result.derived, facts, loose=False) is None)


def weigh_loose(result, verdict, rival, base, sigma, distances, policy):
    """Step 2 for a candidate whose values are loose (`only_loose`): its `Verdict`, admitted
    (objection None) where the data establish it at `Policy.established_sds` twice over, refused
    with the reason otherwise. Its estimate must lie that many sds from the value at which the
    effect is absent (`Policy.established`): a loose size of an effect that is there, not a value
    the data cannot tell from none. And what it predicts of the days no fit read must beat the
    best candidate whose values are tight, `rival`, by that many standard errors of the paired
    difference (`band`'s: the larger of its day-to-day scatter and what the noise alone makes of
    it): a better prediction than a tight candidate within that is one the data do not establish,
    and the value one can act on wins. The weighing is in `Verdict.weighed`."""
    z = policy.established_sds
    name = policy.established(result.parameters, result.physics, result.derived)
    ahead, se = fall(rival.evidence(), result.evidence())
    se = max(se, noise_difference(distances[result.label][rival.label], sigma))
    needed = max(z * se, policy.rounding(float(base.sum())))
    weighed = {"established": name, "against": rival.label, "ahead": ahead, "se": se, "needed": needed,
               "admitted": bool(name is not None and ahead > needed)}
    if weighed["admitted"]:
        return replace(verdict, objection=None, weighed=weighed)
    if name is None:
        why = "; ".join(f"{q} = {value:.3g} +- {sd:.2g} {unit(result, q)} is within {z:g} standard deviations of "
                        f"{null:.3g}, where the effect is absent" for q, (value, sd, null) in
                        policy.absence(result.parameters, result.derived, result.physics).items())
    else:
        why = (f"it predicts what no fit read better than {rival.effect} on {rival.target}, whose values are tight, "
               f"by no more than {z:g} standard errors of the difference (J {result.evidence().sum():.3g} against "
               f"{rival.evidence().sum():.3g} C2, {z:g} x {se:.3g} C2)")
    return replace(verdict, objection=f"{verdict.objection}; {why}", weighed=weighed)


def own_test(own, sigma, policy):
    """A component candidate's test on its own sensors (`result.OwnSensors`, None for another):
    {"fall", "se", "needed", "passes"} (C2), the fall of their J over the blocks from the model to
    the candidate, its standard error from the per-block falls, what it needs (the yardstick of
    step 1 with the noise, sigma (C), and the file's numerical error there in quadrature, and
    `standard_errors` of its scatter), and whether it beats that on more days than its best and
    leaves those sensors at the noise (`Policy.at_noise`, the test that found them disagreeing,
    `windows.Windows.disagreeing`): a correction that moves a surface part of the way and leaves it
    off by more than the noise has not explained it (a fault next to it has: the sun of an
    opening, a neighbour's air), and does not place the fault there.

    A component's own surface measures that sub-model directly, as the paper's forcing of it
    does: where the air no longer points at it (another effect already brings the air to the
    noise) but its own sensor still disagrees, and the component's correction, fitted to the
    air, mends that sensor (which no fit read) without making the air worse beyond the noise's
    margin, the data place a fault there (`candidate_test`)."""
    if own is None or not own.n:
        return None
    before, after = np.asarray(own.before, dtype=float), np.asarray(own.after, dtype=float)
    floor = math.hypot(sigma, own.numerical)
    judged = policy.yardstick.judge(before, after, policy.least_fall(float(before.sum()), floor, own.n))
    mended = policy.at_noise(float(after.sum()), own.n, floor)
    return {"fall": judged.fall, "se": judged.se, "needed": judged.needed, "passes": bool(judged.beats and mended)}


def claim(result, policy):
    """What a candidate's choice claims, least first (`Policy.claim`)."""
    return policy.claim(result.effect, result.physics["component"], result.physics.get("sensed", False))


def band(admissible, base, sigma, floor_sd, n, distances, policy):
    """Step 3: the admissible candidates the data cannot tell from the best (the lowest evidence),
    the best among them: those whose evidence exceeds the best's by no more than
    `standard_errors` standard errors of the paired difference (its scatter from day to day, or
    what the sensors' noise alone makes of it, `noise_difference` of their `distances`), at least
    the rounding; and,
    where the best claims more, by no more than the noise's tolerance (`parsimony`)."""
    best = min(admissible, key=lambda r: r.evidence().sum())
    rounding = policy.rounding(float(base.sum()))

    def close(r):
        worse, se = fall(r.evidence(), best.evidence())
        needed = max(policy.standard_errors * max(se, noise_difference(distances[r.label][best.label], sigma)),
                     rounding)
        if claim(r, policy) < claim(best, policy):
            needed = max(needed, parsimony(best, floor_sd, n, policy))
        return worse <= needed
    return [r for r in admissible if close(r)]


def _reason(chosen, alike, results, passing, base, n, verdicts, margin, components, air_at_noise, policy):
    """The decision in words; `components` the building's component names."""
    B = len(base)
    rmse_before = math.sqrt(base.sum() / n)
    if not results:
        return "No candidate effect was tried, so the model is left as it is."
    if not chosen and air_at_noise:
        return (f"The air's error left is the noise's ({base.sum():.3g} C2 over {B} days); a component's own "
                f"sensors still disagree with the model, but none of the {len(results)} candidates mends them beyond "
                "what the noise and the file's numerical error there could, without making the air worse"
                + (f" ({len(passing)} do, and physics or a record they harm refuses each)" if passing else "")
                + ": no effect is added.")
    if not chosen:
        return (f"None of the {len(results)} candidates lowers the cross-validated J ({base.sum():.3g} C2 over "
                f"{B} days) by more than the noise and the file's numerical error could ({margin:.3g} C2) and "
                f"{policy.standard_errors:g} standard error of its fall from day to day, on more days than one"
                + (f" ({len(passing)} do, and physics or a record they harm refuses each)" if passing else "") + ": no effect is added.")
    what = (f"an unexplained heat source, acting {acting(chosen)} ({chosen.effect} on {chosen.target})"
            if policy.is_shape(chosen.effect) else f"{chosen.effect} on {chosen.target}")
    verdict = verdicts[chosen.label]
    if verdict.passes_by_own and (air_at_noise or not (verdict.cv_fall > verdict.needed and verdict.other_days > 0)):
        own = chosen.sensors.own
        said = (f"{what[0].upper() + what[1:]} mends its own sensors, which no fit read: their J over the {B} days "
                f"falls from {sum(own.before):.3g} to {sum(own.after):.3g} C2 ({own.n} readings), beyond the "
                f"{verdict.own['needed']:.3g} C2 that the noise, the file's numerical error there and the "
                f"day-to-day scatter could make, while the air left out stays within the noise ({base.sum():.3g} -> "
                f"{chosen.cv.J:.3g} C2): the air alone no longer points at {chosen.target}, its own surface does; "
                f"{len(passing)} of {len(results)} candidates pass")
    else:
        said = (f"{what[0].upper() + what[1:]} lowers the cross-validated J from {base.sum():.3g} to "
                f"{chosen.cv.J:.3g} C2 ({rmse_before:.3f} -> {chosen.cv.rmse:.3f} C; each of {B} days "
                f"predicted by a fit to the others), beyond the {verdict.needed:.3g} C2 that the noise, the file's "
                f"numerical error and the day-to-day scatter could make; {len(passing)} of {len(results)} candidates pass")
    sensed = chosen.sensors.n
    if sensed and len(passing) > 1:
        best = min(passing, key=lambda r: r.evidence().sum())
        what = (f"the air left out together with the other sensors over the same days ({sensed} readings no fit "
                f"read; J {best.evidence().sum():.3g} C2")
        # the best predictor may be one physics refuses, or one of the band that claims more
        said += (f"; among them it best predicts {what})" if best is chosen else
                 f"; among them {best.effect} on {best.target} best predicts {what}, against its "
                 f"{chosen.evidence().sum():.3g} C2)"
                 + (f", but is refused: {verdicts[best.label].objection}" if verdicts[best.label].objection else ""))
    said += _weighed(chosen, verdict, {r.label: r for r in results}, policy)
    if alike:
        said += ("; within one standard error of the best, and so not told apart by these data: "
                 + ", ".join(f"{r.effect} on {r.target} ({r.evidence().sum():.3g} C2)" for r in alike)
                 + (" (a physical effect, then fewer parameters, then a zone's effect before one component's, "
                    "is preferred)" if any(r.evidence().sum() < chosen.evidence().sum() for r in alike) else ""))
    others = [r.target for r in alike if r.target != chosen.target and r.target in components]
    if others and chosen.target in components:
        said += (f". The correction of {chosen.target} cannot be told from that of "
                 f"{', '.join(dict.fromkeys(others))}: the fault may be in either")
    elif others:
        said += (f". A correction of {' or '.join(dict.fromkeys(others))} alone explains the data as well: "
                 f"they do not place the fault in one component")
    if policy.is_shape(chosen.effect):
        said += "; no physical effect comes within one standard error of it"
    return said + "."


def _start_reason(start, base, tried, passing):
    """The decision in words where the start is chosen (`start_test`)."""
    said = (f"The start its history leaves unknown, the slow modes' amplitudes at the first measurement fitted "
            f"on the days each block leaves, lowers the cross-validated J from {base.sum():.3g} to "
            f"{start['cv_J']:.3g} C2, beyond the {start['needed']:.3g} C2 that the noise, the file's numerical "
            f"error and the day-to-day scatter could make")
    if "against" in start:
        said += (f"; {_against(start)} ({passing} of {tried} candidates pass), within the {start['band']:.3g} C2 "
                 "that tells a candidate from one that claims less")
    else:
        said += f"; none of the {tried} candidates tried is admitted"
    return (said + ": the start claims nothing about the building and is preferred, so no effect is added in this "
            "round, and the later rounds fit the start with every candidate.")


def _start_beside(start):
    """The clause of the reason where the start is within the band of the effect chosen but the
    policy does not prefer it (`start_test`)."""
    return (f"; the start its history leaves unknown, fitted on the days each block leaves, lowers the "
            f"cross-validated J to {start['cv_J']:.3g} C2, and {_against(start)}, within the {start['band']:.3g} C2 "
            "that tells a candidate from one that claims less: these data cannot tell the effect from a start the "
            "history did not set")


def _against(start):
    """The best admissible candidate's air J against the start's, in words (`start_test`)."""
    effect, target = start["against"].split("@", 1)
    return (f"the best admissible candidate's, {effect} on {target}, is {abs(start['ahead']):.3g} C2 "
            f"{'below' if start['ahead'] >= 0 else 'above'} it on the air")


def _weighed(chosen, verdict, by_label, policy):
    """The clause of the reason on a chosen candidate whose values are loose (`weigh_loose`), ""
    for one whose values are tight: each loose value with its sd, how far the estimate lies from
    the value at which the effect is absent, and what it predicts against the best candidate whose
    values are tight, with that one's values and sds."""
    w = verdict.weighed
    if not w:
        return ""

    def values(fit, estimates):
        return ", ".join(f"{name} = {p.value:.3g} +- {p.sd:.2g} {EFFECTS[fit.effect].parameter(name).unit}"
                         for name, p in estimates.items())
    z, name = policy.established_sds, w["established"]
    loose = policy.loose_values(chosen.effect, chosen.parameters, chosen.derived, chosen.physics)
    value, sd, null = policy.absence(chosen.parameters, chosen.derived, chosen.physics)[name]
    said = (f"; its {values(chosen, loose)} {'is' if len(loose) == 1 else 'are'} loose, but the effect is "
            f"established: {name} lies {abs(value - null) / sd:.3g} standard deviations from {null:.3g}, where "
            f"the effect is absent, beyond {z:g}")
    rival = by_label[w["against"]]
    judged = {k: q for k, q in rival.parameters.items() if k in rival.physics["limits"]}
    return said + (f", and it predicts what no fit read better than the best candidate whose values are tight, "
                   f"{rival.effect} on {rival.target} ({values(rival, judged)}): J {chosen.evidence().sum():.3g} "
                   f"against {rival.evidence().sum():.3g} C2, lower by more than {z:g} standard errors of the "
                   f"difference ({z:g} x {w['se']:.3g} C2): the choice follows the prediction, and the size of "
                   f"{chosen.effect} is as loose as its sd says")


def unit(result, name):
    """The unit of a candidate's parameter or derived quantity `name`."""
    if name in (result.derived or {}):
        return result.derived[name]["unit"]
    return EFFECTS[result.effect].parameter(name).unit


def acting(result):
    """How a shape's heat source acts, in words (its record's `acting`): with a daily profile, or
    in proportion to an input."""
    return EFFECTS[result.effect].acting(result.target, result.values)
