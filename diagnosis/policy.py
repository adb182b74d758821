"""Every threshold, table and order of the diagnosis' choice, in one frozen object (`Policy`),
passed to the loop (`diagnosis.loop.diagnose`'s `policy`) and recorded in report.json
(`Policy.to_json`), so that `diagnosis.result.Diagnosis.replay` judges a report under the values
it was made with. Each field says what it sets and in which unit; how the choice uses them, step
by step: docs/method.md, "Choosing an effect". The noise's yardstick and the pass rule are
`model.score.Yardstick` (`Policy.yardstick`), which the forcing search reads too.
"""
import math
from dataclasses import asdict, dataclass, fields

import numpy as np

from nodeforce.diagnosis.estimate import ParameterEstimate
from nodeforce.model.effects import EFFECTS, member_nodes
from nodeforce.model.score import Yardstick


@dataclass(frozen=True)
class Policy:
    # -- which candidates a round tries (`diagnosis.candidates.physical`)
    # The components the forcing evidence ranks highest whose effects every round calibrates
    # (count): the search's ranking is noisy beyond its first few.
    top_components: int = 3
    # ... and any component whose forcing removes at least this share of J above the noise
    # (dimensionless), however far down the ranking.
    evident_share: float = 0.25

    # -- 1. pass
    # Whole days a calibration window must hold for the cross-validation (days): one fold needs
    # another day to be fitted on.
    min_blocks: int = 2
    # The noise yardstick of a fall of J and the pass rule (`model.score.Yardstick`): how many sds
    # of J of pure noise a change must exceed, the least fall as a share of J, the standard errors
    # of its day-to-day scatter a fall must exceed (and the width of the band of candidates the
    # data cannot tell apart), and the share of J that is rounding; the forcing search's
    # parsimony reads the same.
    yardstick: Yardstick = Yardstick()

    # -- 2. objections
    # A scale parameter, or a derived quantity, is identifiable when its sd is under this share
    # of its value (dimensionless): a fourth is a value one can act on.
    identifiable_share: float = 0.25
    # A temperature (T_ground) is identifiable when its sd is under this (K).
    identifiable_kelvin: float = 1.0
    # A candidate whose values are loose (not identifiable) is admitted only where the data
    # establish it at this many standard errors (dimensionless), twice over
    # (`diagnosis.selection.weigh_loose`): its estimate this many sds from the value that is no
    # effect, and what it predicts of the days no fit read better than the best candidate whose
    # values are tight by this many standard errors of the paired difference; where no tight
    # candidate passes, it is refused. Two: a two-sided 95 % interval, the level `limit_sds`
    # refuses a value at.
    established_sds: float = 2.0
    # Standard deviations of its estimate a value must lie beyond a physical limit to be refused
    # (dimensionless): a door at ten times its wood's conductivity, estimated at 11.4 +- 1.5, may
    # well be at ten; only an estimate whose two-sided 95 % interval leaves the range is not.
    limit_sds: float = 2.0
    # Each effect's physical limits, the parameters it is judged on and what its parameters trade
    # off along are its record's (`model.effects.Effect`: `physical`, `judged`, `trade_off`).

    # -- 3. the band
    # The most a sensor other than the objective air counts in the evidence (dimensionless): a
    # sensor the model follows to the noise counts fully, one it misses by more, sd^2 over its
    # mean squared residual.
    sensor_weight_cap: float = 1.0
    # The time constants of a component (its slowest, as the model describes it:
    # `model.network.slowest_time_constant`) after the burn-in before its candidate's fit reads
    # its own measured nodes (dimensionless): the burn-in sets the measured nodes, not those
    # beside them (a heavy floor's deep layers), and whatever their start misses has fallen to
    # e^-3 = 5 % of it by then.
    start_memory: float = 3.0

    # -- the start (`diagnosis.selection.start_test`)
    # Whether the start a short history leaves unknown, where it passes and the best admissible
    # effect is within the band of it, is chosen in that effect's place (True: the no-fault
    # explanation wins the tie; no effect is added that round, and every later fit fits the
    # start), or only tested and said beside the choice (False). The data cannot tell such an
    # effect from the start; which to prefer is a choice of what to risk: on the benchmark's
    # 7-day test cell records with 0 to 7 days of history (docs/model.md 6.6), preferring the
    # start stops a gain being added to three faultless records and misses a strong gain on
    # three others, a subtle envelope change on two, and the Twin House's subtle shading.
    prefer_start: bool = False

    # -- rounds
    # Effects added at most, one a round (count): a record rarely supports three undeclared effects.
    max_rounds: int = 3
    # The candidates of an earlier round's choice that a revisit calibrates again, the model's
    # other effects refitted with each (`diagnosis.loop.revisit`): the admissible ones nearest it
    # in its round by evidence, itself among them (count). What a later effect can give back is
    # the share of its fault the first choice took; a candidate that explained the round's data
    # far worse would need it to be most of the fault. With two faults, the effect that took a
    # share of both and the one it displaced lead their round.
    revisited: int = 5

    # ---- as report.json records it
    def to_json(self):
        """Every value of the policy as JSON: report.json keeps it,
        so that a replay (`diagnosis.result.Diagnosis.replay`) judges under the values the
        diagnosis was made with, whatever the code's defaults have become since."""
        out = {}
        for f in fields(self):
            value = getattr(self, f.name)
            if f.name == "yardstick":
                value = asdict(value)
            elif isinstance(value, tuple):
                value = list(value)
            out[f.name] = value
        return out

    @classmethod
    def of_json(cls, d):
        """The policy `to_json` wrote; a value it does not hold (a report of a policy with fewer
        values) is the default."""
        def tupled(v):
            return tuple(tupled(x) for x in v) if isinstance(v, list) else v
        given = {}
        for f in fields(cls):
            if f.name not in d:
                continue
            value = d[f.name]
            if f.name == "yardstick":
                value = Yardstick(**value)
            elif isinstance(value, list):
                value = tupled(value)
            given[f.name] = value
        return cls(**given)

    # ---- the yardsticks (`model.score.Yardstick`)
    @property
    def standard_errors(self):
        return self.yardstick.standard_errors

    def noise_J(self, sd, n):
        return self.yardstick.noise_J(sd, n)

    def noise_change(self, sd, n):
        return self.yardstick.noise_change(sd, n)

    def least_fall(self, J, sd, n):
        return self.yardstick.least_fall(J, sd, n)

    def at_noise(self, J, n, sd):
        """Whether an error J (C2) on n residuals is what an error of sd `sd` (C) alone leaves
        (the sensors' noise and the file's numerical error: `model.score.Noise.floor_sd`)."""
        return self.yardstick.at_noise(J, n, sd)

    def rounding(self, J):
        return self.yardstick.rounding(J)

    def identifiable(self, value, sd, unit):
        """Whether an estimate `value` +- `sd` in `unit` is tight enough to act on."""
        return sd < (self.identifiable_kelvin if unit == "C" else self.identifiable_share * abs(value))

    def sensor_weight(self, sd, mean_square):
        """Sensors' weights in the evidence: sd^2 (C2) over each one's mean squared residual (C2,
        an array), at most `sensor_weight_cap`."""
        return np.minimum(self.sensor_weight_cap, sd ** 2 / mean_square)

    # ---- 2. objections
    def is_shape(self, effect):
        """Whether an effect stands for a heat source the model lacks (its record's `shape`)."""
        return EFFECTS[effect].shape

    def limits(self, building, effect, target, name):
        """The physical (low, high) of a parameter: its effect's record's (`Effect.physical`: a
        gain to the air is a source; conductance scales within a factor of ten of the file's; a
        heater or meter off its reading by at most two; a proportional gain's area of sun not
        negative, its share of a heat input not below -1; inside convection within what air can
        give a room)."""
        return EFFECTS[effect].limits_of(building, target, name)

    def judged_parameters(self, effect):
        """The parameters whose identifiability and limits decide for an effect (`Effect.judged`)."""
        return EFFECTS[effect].judged_parameters()

    def facts(self, building, effect, target, sensed=()):
        """What the choice reads of the building about one candidate, as report.json keeps it:
        each judged parameter's physical limits ([low, high], None where unbounded), what the data
        fix where its parameters trade off (`Effect.trade_off`: [derived quantity, whether a
        bound is then waived], None), why the file's description makes the effect implausible
        (`Effect.implausible`, None), the values at which it is absent (`Effect.no_effect_values`)
        and the derived quantities that are 0 there (`Effect.vanishes`), whether its target is one
        component or a group of them (`model.effects.members`) and whether one of their nodes is
        among the `sensed` node ids, the other sensors the evidence reads (`claim`)."""
        nodes = member_nodes(building, target)
        component = bool(nodes)  # a component has nodes; a zone or an input column none
        return {"limits": {name: [None if math.isinf(v) else v for v in self.limits(building, effect, target, name)]
                           for name in self.judged_parameters(effect)},
                "trade_off": list(EFFECTS[effect].trade_off) if EFFECTS[effect].trade_off else None,
                "implausible": implausible(building, effect, target),
                "no_effect": EFFECTS[effect].no_effect_values(building, target),
                "vanishes": list(EFFECTS[effect].vanishes),
                "component": component,
                "sensed": component and bool(set(nodes) & set(sensed))}

    def objection(self, building, effect, target, parameters, derived=None):
        """`objection_of` the candidate's `facts` in `building`."""
        return self.objection_of(effect, parameters, derived, self.facts(building, effect, target))

    def objection_of(self, effect, parameters, derived, facts, loose=True):
        """Why a calibrated effect may not be added to the model, or None: a gain the building
        file's description rules out (`implausible`), a parameter on a bound of its search range
        or, where `loose`, one the data leave loose (`loose_values`), or a value outside physical
        limits beyond its uncertainty (`limit_sds`). The judged parameters, their limits and the
        trade-off are the candidate's `facts`, as report.json records them. A loose value refuses
        a candidate only until the choice has weighed what it predicts (`diagnosis.selection.decide`
        reads the objection without it).

        parameters : {name: `ParameterEstimate`}, or report.json's {"value", "std", "identifiable", "on_bound"}
        derived : what the data determine besides (`diagnosis.calibrate.derived`)
        facts : what the building says of the candidate (`facts`)
        """
        reasons = [facts["implausible"]]
        resolved, bounds_waived = self._resolved(effect, derived, facts)
        for name in facts["limits"]:
            p, unit = ParameterEstimate.of(parameters[name]), EFFECTS[effect].parameter(name).unit
            low, high = (-math.inf if facts["limits"][name][0] is None else facts["limits"][name][0],
                         math.inf if facts["limits"][name][1] is None else facts["limits"][name][1])
            if p.on_bound and not (resolved and bounds_waived):
                reasons.append(f"{name} = {p.value:.3g} {unit} ends on a bound of its range")
            elif loose and not p.identifiable and not resolved and not p.prior:
                reasons.append(f"{name} = {p.value:.3g} +- {p.sd:.2g} {unit} is not identifiable from these data")
            margin = self.limit_sds * p.sd
            if not low - margin <= p.value <= high + margin:
                what = "a negative gain (a heat sink)" if low == 0.0 and EFFECTS[effect].source else "outside physical limits"
                reasons.append(f"{name} = {p.value:.3g} +- {p.sd:.2g} {unit} is {what} [{low:.3g}, {high:.3g}] "
                               f"by more than {self.limit_sds:g} standard deviations")
        return "; ".join(r for r in reasons if r) or None

    def _resolved(self, effect, derived, facts):
        """Whether the quantity the effect's parameters trade off along (`Effect.trade_off`) is
        determined (its sd under `identifiable_share` of it), and whether a bound is then waived."""
        trade_off = facts["trade_off"] if "trade_off" in facts else EFFECTS[effect].trade_off
        key, bounds_waived = trade_off or (None, False)
        fixed = (derived or {}).get(key)
        return fixed is not None and fixed["std"] < self.identifiable_share * abs(fixed["value"]), bounds_waived

    def loose_values(self, effect, parameters, derived, facts):
        """{name: `ParameterEstimate`} of the judged parameters the data leave loose: not
        identifiable (`identifiable`), not on a bound, neither weighed with a prior nor determined
        with the others through the quantity they trade off along."""
        if self._resolved(effect, derived, facts)[0]:
            return {}
        estimates = {name: ParameterEstimate.of(parameters[name]) for name in facts["limits"]}
        return {name: p for name, p in estimates.items() if not p.identifiable and not p.prior and not p.on_bound}

    def absence(self, parameters, derived, facts):
        """{name: (value, sd, value where the effect is absent)} of each quantity that tells the
        effect from none: the parameters at their declared values (`facts`' "no_effect") and the
        derived quantities that are 0 there (`facts`' "vanishes", where `derived` has them; a
        report that predates them says none). A ground coupling's U is as loose as its T_ground
        is, the two trading off along the flux U (T_ground - T_face); the flux the data fix is 0
        only where there is no coupling, whatever T_ground."""
        quantities = {}
        for name, null in (facts.get("no_effect") or {}).items():
            p = ParameterEstimate.of(parameters[name])
            quantities[name] = (p.value, p.sd, null)
        for name in facts.get("vanishes") or ():
            if name in (derived or {}):
                quantities[name] = (derived[name]["value"], derived[name]["std"], 0.0)
        return quantities

    def established(self, parameters, facts, derived=None):
        """The first quantity (name) of `absence` whose estimate lies more than `established_sds`
        of its sd from the value at which the effect is absent, None where every interval includes
        it (or the facts, from a report that predates them, do not say it): the data rule out
        that the effect is not there, however loosely they fix its size. An sd of 0 is a
        covariance that did not come out, not certainty."""
        for name, (value, sd, null) in self.absence(parameters, derived, facts).items():
            if sd > 0 and abs(value - null) > self.established_sds * sd:
                return name
        return None

    # ---- 4. the order
    def claim(self, effect, component, sensed=False):
        """Sort key of what a choice claims, least first: a physical effect before a shape, fewer
        parameters before more, a zone's effect before one component's that no sensor of it
        supports (`component`: its target is one, which says where; `sensed`: one of its nodes is
        measured). A component's own sensor is in the evidence the band judges (the other
        sensors, left out of every fit): where the zone's effect cannot be told from the
        component's even so, the place is no more of a claim than the zone's, and the lower
        evidence chooses; with air alone, nothing but the air speaks for the place."""
        return (self.is_shape(effect), len(EFFECTS[effect].parameters)), bool(component) and not sensed


def implausible(building, effect, target):
    """Why the building file's own description makes an effect implausible (its record's
    `implausible`: a constant gain in a zone the file declares unoccupied stands for a heat source
    the model lacks, not for occupants), or None."""
    record = EFFECTS[effect]
    return record.implausible(building, target) if record.implausible else None
