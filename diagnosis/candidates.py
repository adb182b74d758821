"""Which effects a diagnosis tries, and where their calibrations start: read from each effect's
record (`nodeforce.model.effects.Effect`: which zones offer it, whether it is a shape, where a
parameter declared absent starts); how many components are tried is the policy's
(`diagnosis.policy`).
"""
import math

from nodeforce.model.effects import EFFECTS, bridge_parts, bridge_target, member_table

# How far inside its range (a fraction of it) a calibration starts a value declared on a bound.
INSIDE = 1e-3


def physical(building, evidence, zones, measured_ids, policy, located_nodes=()):
    """(effect, target) pairs every round calibrates, whatever the residual's statistics say: a
    building physicist's list of what could be wrong, which the cross-validated choice
    (`diagnosis.selection`) then judges.

    - Every zone effect of each objective zone (`zone_effects`), and of any zone whose air the
      forcing search located.
    - The component effects (`component_effects`) of the components the forcing evidence ranks
      highest (at least `policy.top_components`, and any removing `policy.evident_share` of J
      above the noise), and of
      every component of an objective zone that no sensor sits in: forcing cannot point at a
      component without a sensor; a calibration can.

    Parameters
    ----------
    building : Building
    evidence : ga.locate's `components`: [{"component", "share", ...}], most evident first
    zones : names of the objective zones
    measured_ids : node ids with a measurement column
    policy : the `diagnosis.policy.Policy`: how many components
    located_nodes : node ids the forcing search located
    """
    located = set(located_nodes)
    air_zones = list(zones) + [z.name for z in building.zones if z.air_node in located]
    pairs = [pair for name in dict.fromkeys(air_zones) for pair in zone_effects(building, name)]
    ranked = [e["component"] for i, e in enumerate(evidence)
              if i < policy.top_components or e["share"] >= policy.evident_share]
    measured = set(measured_ids)
    # a component of an objective zone: one of its faces faces the zone (a partition's either side)
    facing = {i for zone in zones for i in building.facing(zone)}
    unsensed = [c.name for c in building.components if facing & set(c.node_ids) and not measured & set(c.node_ids)]
    for name in dict.fromkeys(ranked + unsensed):
        pairs += component_effects(building, name)
    return list(dict.fromkeys(pairs))


def zone_effects(building, name):
    """The effects the catalogue offers one zone's air (`Effect.offers`), the registry's order: its
    air change with the outside (`thermal_bridge` where the zone has supply air, whose flow is
    known, `infiltration` otherwise) and bridges to the boundary temperatures its surfaces see, a
    constant gain, inside convection, one factor on its envelope, an internal mass, and where it
    has a heat input the heater's lag and the input's split, and where it has shaded glazings
    their shadings' leak; and the house-level effects on it: its supply flow, its heat input's
    reading, the air it exchanges with each zone it shares a component with, and the
    conductances to each boundary column its surfaces or bridges see."""
    return [(effect.id, target) for effect in EFFECTS.values() if effect.offers is not None
            for target in effect.offers(building, name)]


def component_effects(building, name):
    """The effects of one component: those whose target it is (a ground coupling under an
    adiabatic face, its outside absorptance, its conductivity, a glazing's transmittance), or a
    group it is a member of (its construction, a material of it: `model.effects.members`), and a
    glazing's or a glazings' group's transmittance where the component receives its sun; no
    shape (`Effect.shape`). A group is a target of its own, its nodes its members' together."""
    nodes, table = set(building.component(name).node_ids), member_table(building)
    return [(effect.id, target) for effect in EFFECTS.values() if not effect.shape
            for target in effect.targets(building) for group in [table.get(target, ())] if group
            and (name in group or nodes & set(effect.points_at(building, target)))]


def calibration_start(building, effect, target):
    """Where a calibration starts: the declared values, except that an absent coupling (U = 0,
    n = 0, UA = 0, a closed shading's leak f = 0) or an absent zone node (C = 0) starts at its
    record's `absent_start` (`Effect.start`): on its bound, a bounded trust-region step is scaled
    to nothing and the fit stops where it began, and at U = 0 the ground temperature (at C = 0 the
    node's conductance) has no influence to fit at all; an absent door, V = 0, likewise. Any other
    value on or beyond a bound of the range (a heater declared all convective, f_r = 0) starts
    `INSIDE` of the range inside it, for the same reason: declared there, the effect was never
    calibrated. Every value returned is strictly inside the range a calibration explores."""
    values = EFFECTS[effect].start(building, target)
    for p, (low, high) in zip(EFFECTS[effect].parameters, EFFECTS[effect].bounds(building, target)):
        step = INSIDE * (high - low if math.isfinite(high - low) else 1.0)
        if values[p.name] <= low:
            values[p.name] = low + step
        elif values[p.name] >= high:
            values[p.name] = high - step
    return values


def shapes(building, left, zones):
    """The shapes (effect, target) the residual's statistics point at: a gain with a daily
    profile where the residual follows the time of day, one on working days only where it differs
    between working and rest days, a gain proportional to each input column
    it follows (a heat input mis-measured, sun through an opening the model lacks), for each
    objective zone. None where the residual is white: nothing is left to explain. A round tries
    them only where no physical candidate brings the error to the noise (`diagnosis.loop`).

    Parameters
    ----------
    building : Building, the model the residual is of
    left : `diagnosis.residuals.diagnostics` of that residual
    zones : names of the objective zones
    """
    if left.get("white"):
        return []
    # A residual that is structured but follows no input significantly (inputs of one kind, such
    # as the irradiances of several faces, are nearly collinear) still points at that kind: every
    # input a gain may follow is tried, and the clock; the cross-validated choice judges them.
    named = [follows["input"] for follows in left["follows"]]
    clock = (left["time_of_day"] or {}).get("significant", False)
    weekly = left.get("working_days")  # None: the window holds one kind of day
    working = bool(weekly and weekly["significant"])
    if not named:
        named, clock, working = shaped_inputs(building), True, weekly is not None
    pairs = [("daily_gain", zone) for zone in zones] if clock else []
    pairs += [("workday_gain", zone) for zone in zones] if working else []
    targets = EFFECTS["proportional_gain"].targets(building)
    pairs += [("proportional_gain", target) for name in named for zone in zones
              for target in [bridge_target(zone, name)] if target in targets]
    return list(dict.fromkeys(pairs))


def shaped_inputs(building):
    """The input columns a `proportional_gain` may follow (heat inputs, irradiances): the inputs
    a residual is examined against when choosing what to try next."""
    return sorted({bridge_parts(target)[1] for target in EFFECTS["proportional_gain"].targets(building)})
