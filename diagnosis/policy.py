"""Every threshold, table and order of the diagnosis' choice, in one frozen object (`Policy`),
passed to the loop (`diagnosis.loop.diagnose`'s `policy`) and recorded in report.json
(`Policy.to_json`), so that `diagnosis.result.Diagnosis.replay` judges a report under the values
it was made with. Each field says what it sets and in which unit; how the choice uses them, step
by step: docs/method.md, "Choosing an effect". The noise's yardstick and the pass rule are
`model.score.Yardstick` (`Policy.yardstick`), which the forcing search reads too.
"""
import math
from dataclasses import asdict, dataclass, field, fields
from types import MappingProxyType

import numpy as np
from scipy.special import chdtrc

from nodeforce.model.effects import EFFECTS, bridge_parts
from nodeforce.model.score import Yardstick


def _frozen(table):
    return field(default_factory=lambda: MappingProxyType(dict(table)))


@dataclass(frozen=True)
class Policy:
    # -- which candidates a round tries (`diagnosis.candidates.physical`)
    # The components the forcing evidence ranks highest whose effects every round calibrates
    # (count): the search's ranking is noisy beyond its first few.
    top_components: int = 3
    # ... and any component whose forcing removes at least this share of J above the noise
    # (dimensionless), however far down the ranking.
    evident_share: float = 0.25
    # The effects that stand for a heat source the model lacks rather than a property of the
    # building: tried only where no physical effect brings the error to the noise, chosen only
    # where none fits as well.
    shapes: tuple = ("daily_gain", "proportional_gain")

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
    # Standard deviations of its estimate a value must lie beyond a physical limit to be refused
    # (dimensionless): a door at ten times its wood's conductivity, estimated at 11.4 +- 1.5, may
    # well be at ten; only an estimate whose two-sided 95 % interval leaves the range is not.
    limit_sds: float = 2.0
    # Physical limits (low, high) in the parameter's unit, tighter than the range a calibration
    # explores: beyond them a value is a fit compensating something else. A gain to the air is a
    # source (a sink would be a cooler the file declares); conductance scales within a factor of
    # ten of the file's; a heater or meter off its reading by more than two is a fault the file
    # should state.
    physical_limits: MappingProxyType = _frozen({("internal_gain", "Q"): (0.0, math.inf),
                                                 ("daily_gain", "mean"): (0.0, math.inf),
                                                 ("conductivity", "factor"): (0.1, 10.0),
                                                 ("envelope_conductance", "factor"): (0.1, 10.0),
                                                 ("boundary_conductance", "factor"): (0.1, 10.0),
                                                 ("supply_flow", "factor"): (0.1, 10.0),
                                                 ("heat_input_factor", "factor"): (0.5, 2.0)})
    # The area-weighted mean convective coefficient of a room's surfaces that air can give
    # (W/m2/K): natural convection (Alamdari and Hammond) gives a still room about 0.6, forced
    # convection at a hundred air changes an hour (Fisher and Pedersen) stays below 20. A limit
    # on the coefficient, not the factor: a factor of 0.1 is 0.5 W/m2/K where a file declares 5.
    room_convection: tuple = (0.5, 20.0)
    # The parameters whose identifiability decides for an effect (default all): a daily
    # profile's harmonics may each be near zero while its mean is determined.
    judged: MappingProxyType = _frozen({"daily_gain": ("mean",)})
    # What the data fix where an effect's parameters trade off (`diagnosis.calibrate.derived`),
    # and whether a parameter on a bound is then waived: a ground coupling's (U, T_ground) is one
    # of many pairs giving its flux, a bound included; a node's (C, H) and a conductivity factor,
    # judged by their time constant and the heat the component loses, must still be inside.
    trade_offs: MappingProxyType = _frozen({"ground_coupling": ("ground_heat_flux", True),
                                            "conductivity": ("component_loss", False),
                                            "heat_input_lag": ("heater_time_constant", False),
                                            "internal_mass": ("mass_time_constant", False)})

    # -- priors (`diagnosis.calibrate`): where the data fix a combination of an effect's
    # parameters but not each one, a parameter with a physical prior (`model.effects.Prior`) is
    # held at it unless the data reject it at this level (the score test's p-value,
    # dimensionless): the prior is what a modeller would write, and stands until shown wrong.
    prior_level: float = 0.05

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
        """Every value of the policy as JSON (an unbounded limit as null): report.json keeps it,
        so that a replay (`diagnosis.result.Diagnosis.replay`) judges under the values the
        diagnosis was made with, whatever the code's defaults have become since."""
        def bound(v):
            return None if math.isinf(v) else v
        out = {}
        for f in fields(self):
            value = getattr(self, f.name)
            if f.name == "yardstick":
                value = asdict(value)
            elif f.name == "physical_limits":
                value = [[effect, name, bound(low), bound(high)] for (effect, name), (low, high) in value.items()]
            elif isinstance(value, MappingProxyType):
                value = {k: list(v) for k, v in value.items()}
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
            elif f.name == "physical_limits":
                value = MappingProxyType({(effect, name): (-math.inf if low is None else low,
                                                           math.inf if high is None else high)
                                          for effect, name, low, high in value})
            elif isinstance(value, dict):
                value = MappingProxyType({k: tupled(v) for k, v in value.items()})
            elif isinstance(value, list):
                value = tupled(value)
            given[f.name] = value
        return cls(**given)

    def __reduce__(self):
        # a read-only mapping does not pickle: a policy goes to the workers as its JSON
        return (Policy.of_json, (self.to_json(),))

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

    def holds_prior(self, statistic, held):
        """Whether the data leave `held` parameters at their physical priors: the score
        statistic (`diagnosis.calibrate.score_statistic`, chi-square with `held` degrees of
        freedom) has a p-value of at least `prior_level`."""
        return bool(chdtrc(held, statistic) >= self.prior_level)  # the chi-square's survival function

    def sensor_weight(self, sd, mean_square):
        """Sensors' weights in the evidence: sd^2 (C2) over each one's mean squared residual (C2,
        an array), at most `sensor_weight_cap`."""
        return np.minimum(self.sensor_weight_cap, sd ** 2 / mean_square)

    # ---- 2. objections
    def is_shape(self, effect):
        return effect in self.shapes

    def limits(self, building, effect, target, name):
        """The physical (low, high) of a parameter: `physical_limits`; for a proportional gain an
        area of sun that cannot be negative (an irradiance column) or a share of a heat input
        that cannot take away more than the input (k >= -1); for inside convection the factors
        that bring the zone's mean declared coefficient into `room_convection`."""
        if effect == "inside_convection":
            declared = building.mean_inside_convection(target)
            return tuple(h / declared for h in self.room_convection)
        if effect == "proportional_gain":
            _, column = bridge_parts(target)
            heat_inputs = {c for z in building.zones for c in z.heat_input}
            return (-1.0 if column in heat_inputs else 0.0, math.inf)
        return self.physical_limits.get((effect, name), (-math.inf, math.inf))

    def judged_parameters(self, effect):
        """The parameters whose identifiability and limits decide for an effect (`judged`)."""
        return self.judged.get(effect, tuple(p.name for p in EFFECTS[effect].parameters))

    def facts(self, building, effect, target, sensed=()):
        """What the choice reads of the building about one candidate, as report.json keeps it:
        each judged parameter's physical limits ([low, high], None where unbounded), why the
        file's description makes the effect implausible (None), whether its target is one
        component and whether one of that component's nodes is among the `sensed` node ids, the
        other sensors the evidence reads (`claim`)."""
        component = target in {c.name for c in building.components}
        return {"limits": {name: [None if math.isinf(v) else v for v in self.limits(building, effect, target, name)]
                           for name in self.judged_parameters(effect)},
                "implausible": implausible(building, effect, target),
                "component": component,
                "sensed": component and bool(set(building.component(target).node_ids) & set(sensed))}

    def objection(self, building, effect, target, parameters, derived=None):
        """`objection_of` the candidate's `facts` in `building`."""
        return self.objection_of(effect, parameters, derived, self.facts(building, effect, target))

    def objection_of(self, effect, parameters, derived, facts):
        """Why a calibrated effect may not be added to the model, or None: a gain the building
        file's description rules out (`implausible`), a parameter on a bound of its search range
        or not identifiable from the data (unless the quantity its parameters trade off along
        is, `trade_offs`, or the calibration held it at its physical prior), or a value outside
        physical limits beyond its uncertainty (`limit_sds`).

        parameters : {name: {"value", "std", "identifiable", "on_bound"}} of `diagnosis.calibrate`
        derived : what the data determine besides (`diagnosis.calibrate.derived`)
        facts : what the building says of the candidate (`facts`)
        """
        reasons = [facts["implausible"]]
        key, bounds_waived = self.trade_offs.get(effect, (None, False))
        fixed = (derived or {}).get(key)
        resolved = fixed is not None and fixed["std"] < self.identifiable_share * abs(fixed["value"])
        for name in self.judged_parameters(effect):
            p, unit = parameters[name], EFFECTS[effect].parameter(name).unit
            low, high = (-math.inf if facts["limits"][name][0] is None else facts["limits"][name][0],
                         math.inf if facts["limits"][name][1] is None else facts["limits"][name][1])
            if p.get("on_bound") and not (resolved and bounds_waived):
                reasons.append(f"{name} = {p['value']:.3g} {unit} ends on a bound of its range")
            elif not p["identifiable"] and not resolved and not p.get("prior"):
                reasons.append(f"{name} = {p['value']:.3g} +- {p['std']:.2g} {unit} is not identifiable from these data")
            margin = self.limit_sds * p["std"]
            if not low - margin <= p["value"] <= high + margin:
                what = "a negative gain (a heat sink)" if low == 0.0 and "gain" in effect else "outside physical limits"
                reasons.append(f"{name} = {p['value']:.3g} +- {p['std']:.2g} {unit} is {what} [{low:.3g}, {high:.3g}] "
                               f"by more than {self.limit_sds:g} standard deviations")
        return "; ".join(r for r in reasons if r) or None

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
    """Why the building file's own description makes an effect implausible, or None: a constant
    gain in a zone the file declares unoccupied stands for a heat source the model lacks, not for
    occupants, and the report must say so."""
    if effect in ("internal_gain", "daily_gain") and building.zone(target).occupied is False:
        return (f"{target} is declared unoccupied: the gain stands for a heat source the model lacks "
                "(a heat input mis-measured, a flow of air or sun not modelled), not for occupants")
    return None
