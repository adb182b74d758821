"""Which effects a diagnosis tries, and where their calibrations start: the diagnosis' policy.

Kept apart from the effect records (`nodeforce.model.effects`), which an FMU bundles: changing
the policy changes no FMU and throws away no saved search.
"""
import math

from nodeforce.model.effects import EFFECTS, bridge_parts, bridge_target, pair_parts, shaded_glazings
from nodeforce.model.network import RHO_C_AIR

# Where the calibration of an effect the file does not declare starts (see calibration_start).
ABSENT_START = {("ground_coupling", "U"): 1.0,  # W/m2/K
                ("infiltration", "n"): 0.5,  # 1/h
                ("thermal_bridge", "UA"): 5.0,  # W/K
                ("shading_transmittance", "f"): 0.1,  # an external screen's openness and absorbed share
                ("interzone_air_exchange", "V"): 50.0}  # m3/h: a door ajar, or the gap under a closed one
# ... and, for the nodes a zone effect adds, in multiples of the zone air's capacity (J/K): a
# room's furniture and inner mass are several times its air's, an electric heater's about its
# air's; their conductances start at `effects.neutral_conductance` (the air's capacity over
# half an hour), so the mass's time constant starts at hours and the heater's at half an hour.
ZONE_START = {("internal_mass", "C_m"): 10.0,
              ("heat_input_lag", "C_h"): 1.0}


# A scale parameter, or a derived quantity, is identifiable when its standard deviation is under
# this fraction of its value (diagnose.calibrate).
IDENTIFIABLE_RELATIVE = 0.25


def candidates(building, located_nodes, zones):
    """(effect, target) pairs a diagnosis should try.

    Parameters
    ----------
    building : Building
    located_nodes : node ids the forcing search located
    zones : names of the objective zones

    The effects whose forcing points at a located node come first (those of the located
    components, a glazing whose sun they receive, a zone's heat input split when its surfaces are
    located). The air node's own equation is always a candidate, since no forcing can reveal it,
    for the objective zones and any zone whose air was located: a constant gain, and an air-to-
    outside conductance, reported as `thermal_bridge` where the zone has mechanical supply air
    (whose flow is known) and as `infiltration` otherwise (docs/model.md section 7), plus bridges to
    the boundary temperatures the zone's surfaces see, and the house-level effects on its air
    (`house_effects`). When nothing was located, a change of the
    inside convection (no single node) is one as well, and so is one factor on the objective zones'
    envelope (`envelope_conductance`): with nothing localised, the level or slow error that no
    forcing explains may be the whole envelope's conduction rather than the air change. An
    objective zone with shaded glazings is offered the sun its closed shadings let in
    (`shading_leaks`).
    """
    located = set(located_nodes)
    envelope = EFFECTS["envelope_conductance"].targets(building)
    pairs = [(effect.id, target) for effect in EFFECTS.values() for target in effect.targets(building)
             if located & set(effect.points_at(building, target))]
    air_zones = list(zones) + [z.name for z in building.zones if z.air_node in located]
    for name in dict.fromkeys(air_zones):
        supplied = building.zone(name).supply is not None
        if not supplied:
            pairs.append(("infiltration", name))
        pairs.append(("internal_gain", name))
        for target in EFFECTS["thermal_bridge"].targets(building):
            zone, to = bridge_parts(target)
            if zone == name and (to != "outdoor" or supplied):
                pairs.append(("thermal_bridge", target))
        pairs += house_effects(building, name)
    pairs += shading_leaks(building, zones)
    if not located:
        pairs += [("inside_convection", name) for name in zones]
        pairs += [("envelope_conductance", name) for name in zones if name in envelope]
    return list(dict.fromkeys(pairs))


def house_effects(building, zone):
    """The house-level effects on a zone's air: its supply flow, its heat input's reading, the air
    it exchanges with each zone it shares a component with, and the conductances to each boundary
    column its surfaces or bridges see."""
    pairs = [(effect, zone) for effect in ("supply_flow", "heat_input_factor")
             if EFFECTS[effect].applies(building, zone)]
    pairs += [("interzone_air_exchange", t) for t in EFFECTS["interzone_air_exchange"].targets(building)
              if zone in pair_parts(t)]
    seen = [to for t in EFFECTS["thermal_bridge"].targets(building) for z, to in [bridge_parts(t)] if z == zone]
    pairs += [("boundary_conductance", c) for c in EFFECTS["boundary_conductance"].targets(building) if c in seen]
    return pairs


def calibration_start(building, effect, target):
    """Where a calibration starts: the declared values, except that an absent coupling (U = 0,
    n = 0, UA = 0, a closed shading's leak f = 0) starts at `ABSENT_START` and an absent zone node
    (C = 0) at `ZONE_START`: on its bound, a bounded trust-region step is scaled to nothing and the
    fit stops where it began, and at U = 0 the ground temperature (at C = 0 the node's
    conductance) has no influence to fit at all; an absent door, V = 0, likewise."""
    values = EFFECTS[effect].read(building, target)
    for name, value in values.items():
        if value == 0.0 and (effect, name) in ABSENT_START:
            values[name] = ABSENT_START[(effect, name)]
        if value == 0.0 and (effect, name) in ZONE_START:
            values[name] = ZONE_START[(effect, name)] * RHO_C_AIR * building.zone(target).volume
    return values


def implausible(building, effect, target):
    """Why the building file's own description makes an effect implausible, or None: a constant
    gain in a zone the file declares unoccupied stands for a heat source the model lacks, not for
    occupants, and the report must say so."""
    if effect in ("internal_gain", "daily_gain") and building.zone(target).occupied is False:
        return (f"{target} is declared unoccupied: the gain stands for a heat source the model lacks "
                "(a heat input mis-measured, a flow of air or sun not modelled), not for occupants")
    return None


# The shapes: a gain that follows the clock or an input column stands for a heat source the model
# lacks, not for a physical effect of the building; it is chosen only when no physical effect
# comes within the paired margin of it (diagnose.loop.decide).
SHAPES = ("daily_gain", "proportional_gain")

# Physical limits, tighter than the range a calibration explores (model.effects): a value
# outside them is not a property of a building but a fit compensating something else. A gain to
# the air is a source, not a sink (a heat sink would be a cooler the file would declare); scales
# of conductances and convection within a factor of ten of what the file declares.
PHYSICAL_LIMITS = {("internal_gain", "Q"): (0.0, math.inf),
                   ("daily_gain", "mean"): (0.0, math.inf),
                   ("conductivity", "factor"): (0.1, 10.0),
                   ("envelope_conductance", "factor"): (0.1, 10.0),
                   ("inside_convection", "factor"): (0.1, 10.0),
                   ("boundary_conductance", "factor"): (0.1, 10.0),
                   ("supply_flow", "factor"): (0.1, 10.0),
                   # a heater or meter off its reading by more than a factor of two is a fault
                   # the building file should state, not a property to fit
                   ("heat_input_factor", "factor"): (0.5, 2.0)}
# The parameters whose identifiability decides for an effect (default: all of them): a daily
# profile's harmonics may each be near zero, and small next to their uncertainty, while the
# profile and its mean are determined.
JUDGED = {"daily_gain": ("mean",)}


def is_shape(effect):
    return effect in SHAPES


def preference(effect):
    """Sort key of the candidates a decision prefers where the data cannot tell them apart: a
    physical effect before a shape, then fewer parameters before more."""
    return (is_shape(effect), len(EFFECTS[effect].parameters))


def limits(building, effect, target, name):
    """The physical (low, high) of a parameter: PHYSICAL_LIMITS, and for a proportional gain an
    area of sun that cannot be negative (an irradiance column) or a share of a heat input that
    cannot take away more than the input (k >= -1)."""
    if effect == "proportional_gain":
        _, column = bridge_parts(target)
        heat_inputs = {c for z in building.zones for c in z.heat_input}
        return (-1.0 if column in heat_inputs else 0.0, math.inf)
    return PHYSICAL_LIMITS.get((effect, name), (-math.inf, math.inf))


# What the data fix where an effect's parameters trade off (`diagnose.calibrate.derived`): when
# it is determined, the parameters need not be one by one. A ground coupling's (U, T_ground) is
# then one of the many pairs that give the flux, wherever it ended, a bound included; a node's
# (C, H) must still be inside its range, where a bound means a node that is not there.
TRADE_OFFS = {"ground_coupling": ("ground_heat_flux", True),
              "heat_input_lag": ("heater_time_constant", False),
              "internal_mass": ("mass_time_constant", False)}


def objection(building, effect, target, parameters, derived=None):
    """Why a calibrated effect may not be added to the model, or None: a gain the building file's
    description rules out (`implausible`), a parameter on a bound of its search range or not
    identifiable from the data (unless the quantity its parameters trade off along is, TRADE_OFFS),
    or a value outside physical limits.

    parameters : {name: {"value", "std", "identifiable", "on_bound"}} of `diagnose.calibrate`
    derived : what the data determine besides (`diagnose.calibrate.derived`)
    """
    reasons = [implausible(building, effect, target)]
    key, bounds_waived = TRADE_OFFS.get(effect, (None, False))
    fixed = (derived or {}).get(key)
    resolved = fixed is not None and fixed["std"] < IDENTIFIABLE_RELATIVE * abs(fixed["value"])
    for name in JUDGED.get(effect, [p.name for p in EFFECTS[effect].parameters]):
        p, unit = parameters[name], EFFECTS[effect].parameter(name).unit
        low, high = limits(building, effect, target, name)
        if p.get("on_bound") and not (resolved and bounds_waived):
            reasons.append(f"{name} = {p['value']:.3g} {unit} ends on a bound of its range")
        elif not p["identifiable"] and not resolved:
            reasons.append(f"{name} = {p['value']:.3g} +- {p['std']:.2g} {unit} is not identifiable from these data")
        if not low <= p["value"] <= high:
            what = "a negative gain (a heat sink)" if low == 0.0 and "gain" in effect else "outside physical limits"
            reasons.append(f"{name} = {p['value']:.3g} {unit} is {what} [{low:g}, {high:g}]")
    return "; ".join(r for r in reasons if r) or None


def follow_up(building, left, zones):
    """(effect, target) pairs that the structure left in a residual points at: a gain with a daily
    profile where the residual follows the time of day, a gain proportional to an input column it
    follows (a heat input mis-measured, sun through an opening the model lacks), for each
    objective zone, and where that column is the sun on a facade the zone has glazings on, their
    transmittance and their shadings' leak. None where the residual is white: nothing is left to
    explain.

    Parameters
    ----------
    building : Building, the model the residual is of
    left : `diagnose.residuals.diagnostics` of that residual
    zones : names of the objective zones
    """
    if left.get("white"):
        return []
    # A residual that is structured but follows no input significantly (inputs of one kind, such
    # as the irradiances of several faces, are nearly collinear) still points at that kind: every
    # input a gain may follow is tried, and the clock. The decision's rules (BIC, validation)
    # judge what is tried, so trying more costs time, never a wrong answer.
    named = [follows["input"] for follows in left["follows"]]
    clock = (left["time_of_day"] or {}).get("significant", False)
    if not named:
        named, clock = shaped_inputs(building), True
    pairs = [("daily_gain", zone) for zone in zones] if clock else []
    targets = EFFECTS["proportional_gain"].targets(building)
    pairs += [("proportional_gain", target) for name in named for zone in zones
              for target in [bridge_target(zone, name)] if target in targets]
    # a residual that follows a zone's own heat input may also mean its split between air and
    # surfaces is wrong (how fast the air answers the heater)
    pairs += [("heat_input_split", zone) for zone in zones
              if set(named) & set(building.zone(zone).heat_input)]
    pairs += zone_effects(building, left, zones)
    # sun on a facade with glazings: the physical counterparts of a gain following it, the
    # glazings' transmittance and the sun their closed shadings let in
    pairs += [("solar_transmittance", c.name) for c in building.components for zone in zones
              if c.solar_transmittance is not None and c.inside.zone == zone and c.irradiance_input in named]
    pairs += shading_leaks(building, zones, set(named))
    return list(dict.fromkeys(pairs))


def shading_leaks(building, zones, columns=None):
    """("shading_transmittance", zone) for each objective zone whose glazings have a shading and
    that declares no leak yet: a model whose closed blinds block all the sun (the usual
    description, and IDEAS's) misses what a real screen lets through its weave and passes on from
    the heat it absorbs, a gain that follows the sun on those facades only while they are shaded.
    `columns`: only the zones whose shaded glazings read one of these irradiance columns."""
    return [("shading_transmittance", name) for name in zones
            for glazings in [shaded_glazings(building, name)]
            if glazings and building.zone(name).shading_transmittance == 0.0
            and (columns is None or columns & {c.irradiance_input for c in glazings})]


def zone_effects(building, left, zones):
    """The zone effects of docs/model.md section 7 a structured residual points at.

    A residual that follows a zone's own heat input at the same instant is the air answering the
    heater faster in the model than in the building: the classic sign of furniture and internal
    mass and of a heater with its own capacity (Bacher and Madsen 2011), so `internal_mass` and
    `heat_input_lag` of that zone. A level (a mean the residual's own correlation cannot explain)
    or a slow error that follows no input is what the envelope's conduction as a whole would
    leave: `envelope_conductance`. An effect the model already declares is not offered again, so
    after one is added the residual left asks, by the same rules, for the other.

    Parameters
    ----------
    building : Building, the model the residual is of
    left : `diagnose.residuals.diagnostics` of that residual
    zones : names of the objective zones
    """
    instant = {f["input"] for f in left["follows"] if f["lag_hours"] == 0.0}
    pairs = []
    for name in zones:
        zone = building.zone(name)
        if instant & set(zone.heat_input):
            if zone.internal_mass is None:
                pairs.append(("internal_mass", name))
            if zone.heat_input_lag is None:
                pairs.append(("heat_input_lag", name))
    slow = not left["follows"] and not (left["time_of_day"] or {}).get("significant", False)
    if (left.get("level") or {}).get("significant") or slow:
        pairs += [("envelope_conductance", name) for name in zones
                  if name in EFFECTS["envelope_conductance"].targets(building)
                  and building.zone(name).envelope_factor == 1.0]
    return pairs


def shaped_inputs(building):
    """The input columns a `proportional_gain` may follow (heat inputs, irradiances): the inputs
    a residual is examined against when choosing what to try next."""
    return sorted({bridge_parts(target)[1] for target in EFFECTS["proportional_gain"].targets(building)})
