"""The effects a diagnosis may add to a model (docs/model.md section 7): one record per effect.

Each effect is a change of declared fields of the building file, so a model with the effect is
an ordinary building that every command loads, and its FMU exposes the effect's parameters as
`<effect>.<name>`. A record says what the effect adds, its parameters (unit and physical
range), which targets it applies to, how it reads and writes the building, and which nodes'
forcing points at it; and all the diagnosis reads of it (docs/method.md, "Choosing an effect"):
which zones' rounds offer it, where its calibration starts a parameter declared absent, its
physical limits, the parameters it is judged on, what the data fix where its parameters trade
off and the derived quantities that say it, why a building's description may rule it out,
whether it is a shape (a heat source the model lacks) and how it acts, and how it is written back
into an EnergyPlus model (`iotools.energyplus_corrections`). Adding an effect is one record here
(and its fields in the building file format, if it needs new ones). How many candidates a round
tries and the thresholds of the choice are the diagnosis' policy (`nodeforce.diagnosis.policy`).

A surface effect (`conductivity`, `solar_absorptance`, `solar_transmittance`) targets a
component, or where the building file declares its `constructions`, `construction:<name>` (every
component built of it) or, for `conductivity`, `material:<name>` (every layer of it in every
component): one parameter for all its members (`members`). A `thermal_bridge` target is a zone
name for a bridge to the outdoor air, or `<zone>-><column>` for a bridge to a boundary
temperature column (attic, cellar, neighbour); a `proportional_gain`
target is `<zone>-><column>`, the column a heat input or a face's irradiance the building reads;
a `boundary_conductance` target is a boundary temperature column; an `interzone_air_exchange`
target is `<zone>|<zone>`, the two zones in the building file's order.
"""
import math
import re
from dataclasses import dataclass
from typing import Callable

import numpy as np

from .building import DAY_TERMS, WORKDAY_TERMS, Adiabatic, Boundary, Exterior, InsideFace, Surface
from .network import RHO_C_AIR

BRIDGE_TO = "->"
PAIR = "|"


@dataclass(frozen=True)
class Parameter:
    name: str
    unit: str
    low: float  # the range a calibration may explore
    high: float


@dataclass(frozen=True)
class Prior:
    """What physics expects of a parameter the data may leave free: a Gaussian belief of mean
    `value` and standard deviation `sd` (both in the parameter's unit, C for a temperature), and
    where that expectation comes from, in words a report can quote. A fit weighs it against the
    data (`diagnosis.calibrate`, a maximum a posteriori fit); it holds nothing."""
    value: float
    sd: float
    source: str


@dataclass(frozen=True)
class Effect:
    id: str
    adds: str  # what it adds, in a few words
    parameters: tuple  # Parameter records
    targets: Callable  # building -> target names it applies to
    read: Callable  # (building, target) -> {name: value} declared now (neutral if not declared)
    write: Callable  # (JSON data, target, {name: value}) -> None: declare the values
    points_at: Callable  # (building, target) -> node ids whose forcing points at it; () none
    limits: Callable | None = None  # (building, target) -> {name: (low, high)} narrower than the parameters'
    # (building, target, outdoor air (C) over the records read, the annual mean air (C) of the
    # weather read or None) -> {name: Prior}: what physics expects of a parameter, weighed with
    # the data where they fix a combination of the effect's parameters only
    priors: Callable | None = None
    # whether the effect acts on the model's inputs alone (its sources B u + q), affinely in its
    # parameters, the step matrix left as declared: the temperatures are then affine in them
    # (`diagnosis.calibrate.Superposition`)
    on_inputs: bool = False
    # why a standalone FMU cannot expose its parameters (its form is multi-affine in them,
    # fmu_build/standalone.py), or None: it can
    not_standalone: str | None = None

    # -- what the diagnosis reads of it (diagnosis/)
    # (building, zone) -> the targets a round on that zone's air tries (`diagnosis.candidates`);
    # None: offered by its targets among the components the search points at, or as a shape
    offers: Callable | None = None
    # a heat source the model lacks rather than a property of the building: tried only where no
    # physical effect brings the error to the noise, chosen only where none fits as well
    shape: bool = False
    # (building, target) -> {name: value} where a calibration starts a parameter declared 0 (no
    # coupling, no node): on its bound, a bounded step is scaled to nothing
    absent_start: Callable | None = None
    # (building, target) -> {name: (low, high)}: physical limits, tighter than the ranges a
    # calibration explores; beyond them a value is a fit compensating something else
    physical: Callable | None = None
    # the parameters whose identifiability and limits decide for it (None: all)
    judged: tuple | None = None
    # the parameters whose value as the building declares it is the model without the effect, the
    # value an estimate must be told from for the effect to be established (None: all); a
    # coupling's temperature or a node's conductance acts only through another
    no_effect: tuple | None = None
    # the `derived` quantities that are 0 where the effect is absent, whatever the values of its
    # parameters that trade off: where the data fix such a quantity and not the parameters, its
    # distance from 0 is what establishes the effect (`diagnosis.policy.Policy.established`)
    vanishes: tuple = ()
    # Derivation -> {name: {"value", "std", "unit"}}: what the data fix where its parameters
    # trade off (`diagnosis.calibrate.derived`)
    derived: Callable | None = None
    # (one of `derived`'s names, whether a parameter on a bound is waived when that is fixed)
    trade_off: tuple | None = None
    # (building, target) -> why the building file's description rules it out, or None
    implausible: Callable | None = None
    # a heat source: a value below its lower limit of 0 is a sink
    source: bool = False
    # (target, {name: value}) -> how a shape's heat source acts, in words
    acting: Callable | None = None
    # (writer, target) -> None: the correction written into the EnergyPlus model a building was
    # converted from (`iotools.energyplus_corrections`); None: no EnergyPlus object holds it
    energyplus: Callable | None = None

    def applies(self, building, target):
        return target in self.targets(building)

    def bounds(self, building, target):
        """[(low, high)] of each parameter a calibration may explore on this target: the
        parameter's range, narrowed where the target's own size sets a physical limit."""
        narrowed = self.limits(building, target) if self.limits else {}
        return [narrowed.get(p.name, (p.low, p.high)) for p in self.parameters]

    def apply(self, building, target, values):
        """A new Building with the effect declared at `values` ({name: value}; the others as
        declared now)."""
        values = {**self.read(building, target), **values}
        return building.edited(lambda data: self.write(data, target, values))

    def parameter(self, name):
        return next(p for p in self.parameters if p.name == name)

    def limits_of(self, building, target, name):
        """The physical (low, high) of a parameter (`physical`), unbounded where none is said."""
        return (self.physical(building, target) if self.physical else {}).get(name, (-math.inf, math.inf))

    def judged_parameters(self):
        """The parameters whose identifiability and limits decide for it (`judged`, default all)."""
        return self.judged if self.judged is not None else tuple(p.name for p in self.parameters)

    def no_effect_values(self, building, target):
        """{name: value} of the parameters (`no_effect`) at which the effect is absent: as the
        building declares them now (a factor of 1, a gain or a coupling of 0)."""
        declared = self.read(building, target)
        return {name: float(declared[name]) for name in (self.no_effect or declared)}

    def start(self, building, target):
        """Where a calibration starts: the declared values, a parameter declared 0 at its
        `absent_start` where it has one."""
        values = self.read(building, target)
        absent = self.absent_start(building, target) if self.absent_start else {}
        return {name: absent[name] if value == 0.0 and name in absent else value for name, value in values.items()}


CONSTRUCTION, MATERIAL = "construction:", "material:"


def construction_groups(building):
    """{`construction:<name>`: component names} of the file's constructions of two or more
    components: a construction of one is its component's own target."""
    return {CONSTRUCTION + name: names for name, names in building.constructions.items() if len(names) >= 2}


def material_groups(building):
    """{`material:<name>`: names of the components with a layer of it} of each material two or
    more components are made of, where the file declares its constructions (a modeller's file
    names its materials as its constructions do). Not a material that alone makes up exactly the
    components of a construction: scaling it is scaling the construction, offered once."""
    if not building.constructions:
        return {}
    made_of = {}
    for c in building.components:
        for material, _ in c.layers:
            made_of.setdefault(material.name, []).append(c.name)
    whole = {frozenset(names) for names in construction_groups(building).values()}
    alone = {names for names in whole
             if len({m.name for n in names for m, _ in building.component(n).layers}) == 1}
    return {MATERIAL + name: tuple(dict.fromkeys(names)) for name, names in made_of.items()
            if len(set(names)) >= 2 and frozenset(names) not in alone}


def member_table(building):
    """{target: `members`} of every component and group target of a building."""
    return {**{c.name: (c.name,) for c in building.components}, **construction_groups(building),
            **material_groups(building)}


def members(building, target):
    """Names of the components an effect on `target` acts on: the component itself, or every
    component of a construction or material group; () for a target of another kind (a zone, an
    input column)."""
    if target.startswith((CONSTRUCTION, MATERIAL)):
        return member_table(building).get(target, ())
    return (target,) if any(c.name == target for c in building.components) else ()


def _surface_targets(building, applies, materials=False):
    """The components `applies` (Component -> bool) to, then the construction groups all of
    whose members it applies to, then (`materials`) the material groups."""
    names = [c.name for c in building.components if applies(c)]
    ok = set(names)
    groups = [t for t, group in construction_groups(building).items() if ok.issuperset(group)]
    return names + groups + (list(material_groups(building)) if materials else [])


def _members_write(write):
    """`write` of a component field, to every member of a construction target too."""
    def written(data, target, values):
        for name in _members_of_data(data, target):
            write(data, name, values)
    return written


def _members_of_data(data, target):
    """`members` of a construction or component target, read from the building file's JSON."""
    if target.startswith(CONSTRUCTION):
        return data["constructions"][target[len(CONSTRUCTION):]]
    return (target,)


def _first(read):
    """`read` of a component field, of a group its first member's: one parameter for all."""
    return lambda building, target: read(building, members(building, target)[0])


def _component(data, name):
    return next(c for c in data["components"] if c["name"] == name)


def _zone(data, name):
    return next(z for z in data["zones"] if z["name"] == name)


def _zone_field(key, parameter):
    """read and write of an effect that is one number of a zone."""
    def read(building, target):
        return {parameter: float(getattr(building.zone(target), key))}

    def write(data, target, values):
        _zone(data, target)[key] = float(values[parameter])
    return read, write


def _zones(building):
    return [z.name for z in building.zones]


def _heated(building):
    """Zones with a measured heat input."""
    return [z.name for z in building.zones if z.heat_input]


def member_nodes(building, target):
    """The node ids of the components an effect on `target` acts on (`members`), in order."""
    return tuple(i for name in members(building, target) for i in building.component(name).node_ids)


def _no_node(building, target):
    return ()


# ground coupling: an adiabatic face becomes a `boundary` at T_ground through U (W/m2/K)
def _ground_read(building, target):
    out = building.component(target).outside
    if isinstance(out, Boundary) and not isinstance(out.temperature, str):
        return {"U": out.h, "T_ground": out.temperature}
    return {"U": 0.0, "T_ground": 20.0}


def _ground_write(data, target, values):
    # U = 0 is no coupling: the face stays as declared; any other U, negative or NaN too, is
    # declared, and the building's own check refuses what is not a conductance
    if values["U"] != 0:
        _component(data, target)["outside"] = {"type": "boundary", "temperature": float(values["T_ground"]),
                                               "h": float(values["U"])}


def _passes_no_heat(component):
    """Whether a component's outside face passes no heat out of the building: `adiabatic`, or held
    at its own inside face's temperature (`inside_face`: EnergyPlus's Adiabatic surface), an
    internal mass (a zone's furniture, not its envelope) excepted."""
    return (isinstance(component.outside, Adiabatic)
            or (isinstance(component.outside, InsideFace) and component.inside.face_class != "internal_mass"))


# The spread (K) of each estimate of the deep ground (`deep_ground_temperature`): a modeller's
# declared value is the site's typical-year mean air, which the ground a few metres down follows to
# a degree or two (EnergyPlus's deep ground temperature); a year of the site's own weather gives
# that mean to within its year-to-year swing and the ground's offset from the air; a few weeks'
# mean air misses the annual mean by up to the season's amplitude, some 5 to 10 K in mid-summer or
# mid-winter at a mid-latitude site.
DECLARED_GROUND_SD = 1.5
ANNUAL_AIR_SD = 2.0
RECORD_AIR_SD = 5.0


def deep_ground_temperature(building, outdoor_air, annual_air=None):
    """The `Prior` (C) of the ground a few metres down, where the seasons no longer reach: the
    site's `ground_temperature` where the building file declares one (sd `DECLARED_GROUND_SD`),
    else the annual mean outdoor air of the weather the diagnosis reads where that weather spans
    a year or more (`annual_air`, C, or None; sd `ANNUAL_AIR_SD`), else the mean of the outdoor
    air temperatures given (C, any shape; NaN ignored), the records and their history, with the
    wide sd `RECORD_AIR_SD`: a few weeks' mean is the annual mean only in spring and autumn."""
    declared = building.site.get("ground_temperature")
    if declared is not None:
        return Prior(float(declared), DECLARED_GROUND_SD, "the site's ground temperature, as the building file "
                                                          "declares it")
    if annual_air is not None:
        return Prior(float(annual_air), ANNUAL_AIR_SD, "the annual mean outdoor air temperature of the weather "
                                                       "read, the deep-ground estimate")
    return Prior(float(np.nanmean(outdoor_air)), RECORD_AIR_SD,
                 "the mean outdoor air temperature of the records and their history, a rough deep-ground "
                 "estimate (the weather read spans less than a year)")


def _ground_priors(building, target, outdoor_air, annual_air=None):
    return {"T_ground": deep_ground_temperature(building, outdoor_air, annual_air)}


@_members_write
def _absorptance_write(data, target, values):
    _component(data, target)["outside"]["solar_absorptance"] = float(values["alpha"])


def _conductivity_read(building, target):
    if target.startswith(MATERIAL):
        name = target[len(MATERIAL):]
        return {"factor": next(m.conductivity_factor for c in building.components for m, _ in c.layers
                               if m.name == name)}
    return {"factor": building.component(members(building, target)[0]).conductivity_factor}


@_members_write
def _component_conductivity_write(data, target, values):
    _component(data, target)["conductivity_factor"] = float(values["factor"])


def _conductivity_write(data, target, values):
    if target.startswith(MATERIAL):
        data["materials"][target[len(MATERIAL):]]["conductivity_factor"] = float(values["factor"])
    else:
        _component_conductivity_write(data, target, values)


@_members_write
def _transmittance_write(data, target, values):
    _component(data, target)["solar_transmittance"] = float(values["tau"])


def _receiver_nodes(building, target):
    receivers = dict.fromkeys(r for name in members(building, target) for r in building.component(name).sun_receivers)
    return tuple(i for name in receivers for i in building.component(name).node_ids)


# thermal bridge: a conductance UA from a zone's air to the outdoor air or a boundary column
def bridge_target(zone, to="outdoor"):
    return zone if to == "outdoor" else f"{zone}{BRIDGE_TO}{to}"


def bridge_parts(target):
    """(zone, "outdoor" or column) of a thermal_bridge target."""
    zone, _, to = target.partition(BRIDGE_TO)
    return zone, to or "outdoor"


def _bridge_targets(building):
    """Each zone to the outdoor air and to every boundary column its surfaces see."""
    targets = []
    for z in building.zones:
        columns = [c.outside.temperature for c in building.components
                   if c.inside.zone == z.name and isinstance(c.outside, Boundary)
                   and isinstance(c.outside.temperature, str)]
        columns += [to for to, _ in z.thermal_bridges if to != "outdoor"]
        targets += [bridge_target(z.name, to) for to in dict.fromkeys(["outdoor", *columns])]
    return targets


def _bridge_read(building, target):
    zone, to = bridge_parts(target)
    return {"UA": float(dict(building.zone(zone).thermal_bridges).get(to, 0.0))}


def _bridge_write(data, target, values):
    zone, to = bridge_parts(target)
    _zone(data, zone).setdefault("thermal_bridges", {})[to] = float(values["UA"])


# daily gain: a zone's gain with a daily profile, its mean (the zone's internal_gain, the one field
# for a constant gain) and its harmonics of the local clock time (the zone's daily_gain): a
# schedule's mean is part of it, and a profile fitted without its mean would miss the gain itself.
def _daily_read(building, target):
    zone = building.zone(target)
    return {"mean": zone.internal_gain, **dict.fromkeys(DAY_TERMS, 0.0), **dict(zone.daily_gain)}


def _daily_write(data, target, values):
    zone = _zone(data, target)
    zone["internal_gain"] = float(values["mean"])
    zone["daily_gain"] = {t: float(values[t]) for t in DAY_TERMS}


# workday gain: a zone's gain on working days only, its own mean and harmonics of the local clock
# time (the zone's workday_gain); the zone's constant internal_gain is apart from it.
def _workday_read(building, target):
    return {**dict.fromkeys(WORKDAY_TERMS, 0.0), **dict(building.zone(target).workday_gain)}


def _workday_write(data, target, values):
    _zone(data, target)["workday_gain"] = {t: float(values[t]) for t in WORKDAY_TERMS}


# proportional gain: Q = k u_column to a zone's air, for a column the building reads as a heat
# input (W, k dimensionless) or a face's irradiance (W/m2, k an area in m2)
def _proportional_targets(building):
    columns = [name for z in building.zones for name in z.heat_input]
    columns += [c.irradiance_input for c in building.exterior_components]
    return [f"{z.name}{BRIDGE_TO}{column}" for z in building.zones for column in dict.fromkeys(columns)]


def _proportional_read(building, target):
    zone, _, column = target.partition(BRIDGE_TO)
    return {"k": float(dict(building.zone(zone).proportional_gains).get(column, 0.0))}


def _proportional_write(data, target, values):
    zone, _, column = target.partition(BRIDGE_TO)
    _zone(data, zone).setdefault("proportional_gains", {})[column] = float(values["k"])


# internal mass, heater lag: a node of capacity C coupled to the zone by H (docs/model.md section 7).
# Not declared, the node is neutral: no capacity, so it holds the zone's temperature and carries
# no heat (the heater passes its input on at once); its conductance is then any positive value,
# the zone air's capacity over NEUTRAL_TIME, a magnitude a calibration may start from.
NEUTRAL_TIME = 1800.0  # s


def neutral_conductance(building, zone):
    """W/K: a coupling of the magnitude of the zone's air capacity over `NEUTRAL_TIME`."""
    return RHO_C_AIR * building.zone(zone).volume / NEUTRAL_TIME


def _lumped_field(key, capacity, conductance):
    """read and write of a zone effect that adds a node (`building.Lumped` under `key`)."""
    def read(building, target):
        declared = getattr(building.zone(target), key)
        if declared is None:
            return {capacity: 0.0, conductance: neutral_conductance(building, target)}
        return {capacity: declared.capacity, conductance: declared.conductance}

    def write(data, target, values):
        _zone(data, target)[key] = {"capacity": float(values[capacity]), "conductance": float(values[conductance])}
    return read, write


# A zone's furniture and inner mass, or its heater, hold at most this many times its air's heat
# capacity (furnishing is 10 to 80 kg per m2 of floor, some 10 to 40 times the air's capacity; a
# floor heating's screed about 50): more would be a reservoir at the record's first temperature,
# a constant gain in disguise, not a mass.
MAX_AIR_CAPACITIES = 100.0


def _lumped_limits(capacity):
    def limits(building, target):
        return {capacity: (0.0, MAX_AIR_CAPACITIES * RHO_C_AIR * building.zone(target).volume)}
    return limits


def _envelope_targets(building):
    """Zones with a component to the outdoors or a boundary: what an envelope factor scales."""
    return [z.name for z in building.zones
            if any(c.inside.zone == z.name and isinstance(c.outside, (Exterior, Boundary)) for c in building.components)]


def shaded_glazings(building, zone):
    """The glazed components of a zone whose sun a shading column scales."""
    return [c for c in building.components if c.shading and c.inside.zone == zone]


def _shading_targets(building):
    """Zones with a glazing whose sun a shading column scales: what a closed shading's leak acts on."""
    return [z.name for z in building.zones if shaded_glazings(building, z.name)]


def _shading_receivers(building, target):
    return tuple(i for c in shaded_glazings(building, target)
                 for name in c.sun_receivers for i in building.component(name).node_ids)


# boundary conductance: one factor on every conductance from the building to a boundary column
def _boundary_components(building, column):
    return [c for c in building.components
            if isinstance(c.outside, Boundary) and c.outside.temperature == column]


def _boundary_read(building, target):
    return {"factor": building.boundary_factor(target)}


def _boundary_write(data, target, values):
    data.setdefault("boundary_conductance_factors", {})[target] = float(values["factor"])


def _boundary_nodes(building, target):
    return tuple(i for c in _boundary_components(building, target) for i in c.node_ids)


# supply flow: a factor on a zone's mechanical supply flow
def _supply_targets(building):
    return [z.name for z in building.zones if z.supply is not None and z.supply.flow > 0]


def _supply_read(building, target):
    return {"factor": building.zone(target).supply.flow_factor}


def _supply_write(data, target, values):
    _zone(data, target)["supply"]["flow_factor"] = float(values["factor"])


# interzone air exchange: a flow V each way between two zones' air, through an open internal door
def pair_target(a, b):
    return f"{a}{PAIR}{b}"


def pair_parts(target):
    """(zone, zone) of an `interzone_air_exchange` target."""
    a, _, b = target.partition(PAIR)
    return a, b


def _pair_targets(building):
    """Each pair of zones that share a component (a partition, an internal door), and each pair
    that declares an exchange, the two in the building file's order."""
    order = {z.name: k for k, z in enumerate(building.zones)}
    pairs = [(c.inside.zone, c.outside.zone) for c in building.components
             if isinstance(c.outside, Surface) and c.outside.zone != c.inside.zone]
    pairs += [(z.name, other) for z in building.zones for other, _ in z.air_exchange]
    return list(dict.fromkeys(pair_target(*sorted(p, key=order.get)) for p in pairs))


def _pair_read(building, target):
    a, b = pair_parts(target)
    declared = {**{(a, o): V for o, V in building.zone(a).air_exchange},
                **{(b, o): V for o, V in building.zone(b).air_exchange}}
    return {"V": float(declared.get((a, b), declared.get((b, a), 0.0)))}


def _pair_write(data, target, values):
    a, b = pair_parts(target)
    # where the file declares it, else on the first of the two zones
    owner = b if a in _zone(data, b).get("air_exchange", {}) else a
    _zone(data, owner).setdefault("air_exchange", {})[b if owner == a else a] = float(values["V"])


# -- what the diagnosis reads of the effects (see `Effect`)

def _offered(targets):
    """`offers` of a zone effect whose target is the zone itself, where it applies."""
    return lambda building, zone: [zone] if zone in targets(building) else []


def _infiltration_offers(building, zone):
    """A zone's air change, where no supply air of known flow is its exchange with the outside."""
    return [] if building.zone(zone).supply is not None else [zone]


def _bridge_offers(building, zone):
    """A zone's bridges to the boundary columns its surfaces see, and to the outdoor air where its
    supply air, whose flow is known, leaves no air change to try."""
    supplied = building.zone(zone).supply is not None
    return [t for t in _bridge_targets(building) for owner, to in [bridge_parts(t)]
            if owner == zone and (to != "outdoor" or supplied)]


def _pair_offers(building, zone):
    """The air a zone exchanges with each zone it shares a component with."""
    return [t for t in _pair_targets(building) if zone in pair_parts(t)]


def _boundary_offers(building, zone):
    """The conductances to each boundary column a zone's surfaces or bridges see."""
    seen = {to for t in _bridge_targets(building) for z, to in [bridge_parts(t)] if z == zone}
    seen |= {getattr(c.outside, "temperature", None) for c in building.components if c.inside.zone == zone}
    return [c for c in building.boundary_columns if c in seen]


def _absent(**values):
    """`absent_start` of fixed values."""
    return lambda building, target: values


def _air_capacities(name, multiple):
    """`absent_start` of a node a zone effect adds: `multiple` times the zone air's capacity (J/K): a
    room's furniture and inner mass are several times its air's, an electric heater's about its
    air's; their conductances start at `neutral_conductance`, so the mass's time constant starts
    at hours and the heater's at half an hour."""
    return lambda building, target: {name: multiple * RHO_C_AIR * building.zone(target).volume}


def _fixed_limits(**limits):
    """`physical` of fixed (low, high) per parameter."""
    return lambda building, target: limits


# A conductance scales within a factor of ten of the file's; a heater or meter off its reading by
# more than two is a fault the file should state.
SCALE_LIMITS = (0.1, 10.0)
READING_LIMITS = (0.5, 2.0)
# The area-weighted mean convective coefficient of a room's surfaces that air can give (W/m2/K):
# natural convection (Alamdari and Hammond) gives a still room about 0.6, forced convection at a
# hundred air changes an hour (Fisher and Pedersen) stays below 20. A limit on the coefficient, not
# the factor: a factor of 0.1 is 0.5 W/m2/K where a file declares 5.
ROOM_CONVECTION = (0.5, 20.0)


def _convection_limits(building, target):
    declared = building.mean_inside_convection(target)
    return {"factor": tuple(h / declared for h in ROOM_CONVECTION)}


def _proportional_limits(building, target):
    """An area of sun cannot be negative (an irradiance column); a share of a heat input cannot
    take away more than the input (k >= -1)."""
    _, column = bridge_parts(target)
    heat_inputs = {c for z in building.zones for c in z.heat_input}
    return {"k": (-1.0 if column in heat_inputs else 0.0, math.inf)}


def _unoccupied(building, target):
    """A constant gain in a zone the file declares unoccupied stands for a heat source the model
    lacks, not for occupants, and the report must say so."""
    if building.zone(target).occupied is False:
        return (f"{target} is declared unoccupied: the gain stands for a heat source the model lacks "
                "(a heat input mis-measured, a flow of air or sun not modelled), not for occupants")
    return None


def _ground_flux(d):
    """A ground coupling acts through its heat flux density q = U (T_ground - T_face) (W/m2, into
    the component), T_face the face's mean temperature simulated over the window: many (U,
    T_ground) pairs give the same flux."""
    face = d.building.component(d.target).node_ids[-1]

    def flux(values):
        U, T_ground = values[:2]
        return U * (T_ground - float(np.mean(d.nodes([face], values))))
    return {"ground_heat_flux": d.of(flux, "W/m2")}


def _component_loss(d):
    """A component's conductivity factor acts through the heat the component loses (W/K): the HLC
    with the factor less the HLC with the factor at its lower bound."""
    low = d.bounds[0][0]
    return {"component_loss": d.with_sd(d.hlc - d.hlc_at([low, *d.x[1:]]), d.hlc_slope, "W/K")}


def _time_constant(name):
    """A node of capacity C coupled by H answers with its time constant tau = C / H (s)."""
    def derived(d):
        C, H = d.x[:2]
        return {name: d.with_sd(C / H, np.r_[1.0 / H, -C / H ** 2, np.zeros(len(d.x) - 2)], "s")}
    return derived


def _profile_acting(when, over):
    """The `acting` words of a gain with a daily profile: `when` it acts, the mean `over` what."""
    def acting(target, values):
        amplitude = math.hypot(values.get("cos1", 0.0), values.get("sin1", 0.0))
        return (f"{when}with a daily profile (mean {values['mean']:.3g} W{over}, first harmonic {amplitude:.3g} W) "
                f"to the air of {target}")
    return acting


def _proportional_acting(target, values):
    zone, column = bridge_parts(target)
    return f"in proportion to {column} (k = {values['k']:.3g}) to the air of {zone}"


EFFECTS = {e.id: e for e in (
    Effect("ground_coupling", "a conductance from an adiabatic face to a ground temperature",
           (Parameter("U", "W/m2/K", 0.0, 20.0), Parameter("T_ground", "C", -10.0, 40.0)),
           lambda b: [c.name for c in b.components if _passes_no_heat(c)],
           _ground_read, _ground_write, member_nodes, priors=_ground_priors,
           absent_start=_absent(U=1.0), derived=_ground_flux, trade_off=("ground_heat_flux", True),
           no_effect=("U",), vanishes=("ground_heat_flux",)),
    Effect("infiltration", "an air change with the outside",
           (Parameter("n", "1/h", 0.0, 20.0),), _zones,
           *_zone_field("air_change_rate", "n"), _no_node,
           offers=_infiltration_offers, absent_start=_absent(n=0.5), energyplus=lambda w, t: w.infiltration(t)),
    Effect("internal_gain", "a constant heat gain to the air",
           (Parameter("Q", "W", -5000.0, 5000.0),), _zones,
           *_zone_field("internal_gain", "Q"), _no_node, on_inputs=True,
           offers=_offered(_zones), physical=_fixed_limits(Q=(0.0, math.inf)), implausible=_unoccupied, source=True,
           energyplus=lambda w, t: w.internal_gain(t)),
    Effect("solar_absorptance", "a corrected outside solar absorptance",
           (Parameter("alpha", "-", 0.0, 1.0),),
           lambda b: _surface_targets(b, lambda c: isinstance(c.outside, Exterior)),
           _first(lambda b, t: {"alpha": b.component(t).outside.solar_absorptance}), _absorptance_write, member_nodes,
           on_inputs=True, energyplus=lambda w, t: w.solar_absorptance(t)),
    Effect("conductivity", "a scale on a component's conductances",
           (Parameter("factor", "-", 0.05, 20.0),), lambda b: _surface_targets(b, lambda c: True, materials=True),
           _conductivity_read, _conductivity_write, member_nodes,
           physical=_fixed_limits(factor=SCALE_LIMITS), derived=_component_loss, trade_off=("component_loss", False),
           energyplus=lambda w, t: w.conductivity(t)),
    Effect("inside_convection", "a scale on the inside convective coefficients",
           (Parameter("factor", "-", 0.01, 20.0),), _zones,
           *_zone_field("convection_factor", "factor"), _no_node,
           offers=_offered(_zones), physical=_convection_limits),
    Effect("solar_transmittance", "a corrected transmittance of a glazing",
           (Parameter("tau", "-", 0.0, 1.0),),
           lambda b: _surface_targets(b, lambda c: c.solar_transmittance is not None),
           _first(lambda b, t: {"tau": b.component(t).solar_transmittance}), _transmittance_write, _receiver_nodes,
           on_inputs=True, energyplus=lambda w, t: w.solar_transmittance(t)),
    Effect("thermal_bridge", "a conductance from a zone's air to the outdoor air or a boundary temperature",
           (Parameter("UA", "W/K", 0.0, 200.0),), _bridge_targets, _bridge_read, _bridge_write, _no_node,
           offers=_bridge_offers, absent_start=_absent(UA=5.0)),
    Effect("heat_input_split", "a corrected radiative fraction of a zone's measured heat input",
           (Parameter("f_r", "-", 0.0, 1.0),), _heated,
           *_zone_field("heat_input_radiative_fraction", "f_r"),
           lambda b, t: b.facing(t), on_inputs=True, offers=_offered(_heated)),
    Effect("internal_mass", "the zone's furniture and undeclared internal mass: a node coupled to its air, a face of the zone",
           (Parameter("C_m", "J/K", 0.0, 1e9), Parameter("H_m", "W/K", 0.01, 1e5)), _zones,
           *_lumped_field("internal_mass", "C_m", "H_m"), _no_node, _lumped_limits("C_m"),
           offers=_offered(_zones), absent_start=_air_capacities("C_m", 10.0),
           derived=_time_constant("mass_time_constant"), trade_off=("mass_time_constant", False),
           no_effect=("C_m",), energyplus=lambda w, t: w.internal_mass(t),
           not_standalone="its parameters move the mass's face in the zone's long-wave exchange and sun split, "
                          "not affinely"),
    Effect("heat_input_lag", "the heater's own capacity: a node between its measured heat input and the zone",
           (Parameter("C_h", "J/K", 0.0, 1e8), Parameter("H_h", "W/K", 0.01, 1e5)),
           _heated, *_lumped_field("heat_input_lag", "C_h", "H_h"), _no_node, _lumped_limits("C_h"),
           offers=_offered(_heated), absent_start=_air_capacities("C_h", 1.0),
           derived=_time_constant("heater_time_constant"), trade_off=("heater_time_constant", False),
           no_effect=("C_h",)),
    Effect("envelope_conductance", "the envelope's materials conducting other than declared: one factor on "
                                   "the layer conductances of a zone's components to the outdoors and to "
                                   "boundaries, not their outside surface coefficients",
           (Parameter("factor", "-", 0.05, 20.0),), _envelope_targets,
           *_zone_field("envelope_factor", "factor"), _no_node,
           offers=_offered(_envelope_targets), physical=_fixed_limits(factor=SCALE_LIMITS)),
    Effect("shading_transmittance", "the part of a glazing's sun that the zone's closed shading devices "
                                    "still let in (a screen's openness, the heat a blind absorbs and passes on)",
           (Parameter("f", "-", 0.0, 1.0),), _shading_targets,
           *_zone_field("shading_transmittance", "f"), _shading_receivers, on_inputs=True,
           offers=_offered(_shading_targets), absent_start=_absent(f=0.1)),
    Effect("daily_gain", "a heat gain to the air with a daily profile: its mean and harmonics of the local time",
           (Parameter("mean", "W", -5000.0, 5000.0), *(Parameter(t, "W", -5000.0, 5000.0) for t in DAY_TERMS)),
           _zones, _daily_read, _daily_write, _no_node, on_inputs=True,
           shape=True, physical=_fixed_limits(mean=(0.0, math.inf)), judged=("mean",), implausible=_unoccupied,
           source=True, acting=_profile_acting("", "")),
    Effect("workday_gain", "a heat gain to the air on working days only (Monday to Friday, local time), with a "
                           "daily profile: its mean and harmonics of the local time",
           tuple(Parameter(t, "W", -5000.0, 5000.0) for t in WORKDAY_TERMS),
           _zones, _workday_read, _workday_write, _no_node, on_inputs=True,
           shape=True, physical=_fixed_limits(mean=(0.0, math.inf)), judged=("mean",), implausible=_unoccupied,
           source=True, acting=_profile_acting("on working days only, ", " over a working day"),
           energyplus=lambda w, t: w.workday_gain(t)),
    Effect("proportional_gain", "a heat gain to the air of k times an input column (W per unit of the column: "
                                "dimensionless for a heat input, m2 for an irradiance)",
           (Parameter("k", "-", -10.0, 10.0),), _proportional_targets, _proportional_read, _proportional_write,
           _no_node, on_inputs=True, shape=True, physical=_proportional_limits, source=True,
           acting=_proportional_acting),
    Effect("boundary_conductance", "one factor on every conductance from the building to a boundary temperature "
                                   "column (attic, cellar, a neighbour): its components' layers and outside "
                                   "coefficients, and the zones' thermal bridges to it",
           (Parameter("factor", "-", 0.05, 20.0),), lambda b: list(b.boundary_columns),
           _boundary_read, _boundary_write, _boundary_nodes,
           offers=_boundary_offers, physical=_fixed_limits(factor=SCALE_LIMITS)),
    Effect("supply_flow", "a factor on a zone's mechanical supply air flow",
           (Parameter("factor", "-", 0.0, 10.0),), _supply_targets, _supply_read, _supply_write, _no_node,
           offers=_offered(_supply_targets), physical=_fixed_limits(factor=SCALE_LIMITS)),
    Effect("interzone_air_exchange", "air exchanged between two zones, a flow each way (an open internal door)",
           (Parameter("V", "m3/h", 0.0, 3000.0),), _pair_targets, _pair_read, _pair_write, _no_node,
           offers=_pair_offers, absent_start=_absent(V=50.0)),
    Effect("heat_input_factor", "a factor on a zone's measured heat input: the heat its heater delivers per W read",
           (Parameter("factor", "-", 0.0, 5.0),), _heated,
           *_zone_field("heat_input_factor", "factor"), _no_node, on_inputs=True,
           offers=_offered(_heated), physical=_fixed_limits(factor=READING_LIMITS)),
)}


@dataclass(frozen=True)
class Property:
    """A number of the building file that every FMU exposes as the parameter `<target>.<name>`
    (its start the declared value): what another tool may calibrate. Where an effect of the
    registry already reads and writes that number, the property is that effect's parameter."""
    name: str
    of: str  # "component" or "zone"
    parameter: Parameter  # its unit and the range an FMU declares (min, max)
    targets: Callable  # building -> the component or zone names it applies to
    read: Callable  # (building, target) -> value declared now
    write: Callable  # (JSON data, target, value) -> None
    reach: Callable  # (building, target) -> ids of the nodes whose rows of the network it changes

    def bounds(self, start):
        """(min, max) an FMU declares: the parameter's range, widened to hold the declared value."""
        return min(self.parameter.low, start), max(self.parameter.high, start)


def _effect_property(name, of, effect_id, reach):
    effect = EFFECTS[effect_id]
    parameter, = effect.parameters
    return Property(name, of, parameter, effect.targets, lambda b, t: float(effect.read(b, t)[parameter.name]),
                    lambda data, t, value: effect.write(data, t, {parameter.name: value}), reach)


def _air_node(building, target):
    return (building.zone(target).air_node,)


def _zone_surfaces(building, target):
    return (building.zone(target).air_node, *building.facing(target))


def _capacity_write(data, target, value):
    _component(data, target)["capacity_factor"] = float(value)


PROPERTIES = (
    _effect_property("conductivity_factor", "component", "conductivity", member_nodes),
    Property("capacity_factor", "component", Parameter("factor", "-", 0.05, 20.0), lambda b: [c.name for c in b.components],
             lambda b, t: float(b.component(t).capacity_factor), _capacity_write, member_nodes),
    _effect_property("solar_absorptance", "component", "solar_absorptance", member_nodes),
    _effect_property("solar_transmittance", "component", "solar_transmittance", _receiver_nodes),
    _effect_property("air_change_rate", "zone", "infiltration", _air_node),
    _effect_property("internal_gain", "zone", "internal_gain", _air_node),
    _effect_property("h_conv_factor", "zone", "inside_convection", _zone_surfaces),
)


def properties(building):
    """[(FMU parameter name, Property, target)] of a building, components' then zones', in the
    building's order."""
    targets = [set(p.targets(building)) for p in PROPERTIES]
    names = {"component": [c.name for c in building.components], "zone": [z.name for z in building.zones]}
    return [(f"{structured_name(name)}.{p.name}", p, name) for of in ("component", "zone") for name in names[of]
            for p, applies in zip(PROPERTIES, targets) if p.of == of and name in applies]


def structured_name(name):
    """A component's or zone's name as one part of an FMI structured name: itself where it is an
    identifier, else quoted (FMI's q-name: between single quotes, ' and \\ escaped)."""
    if re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", name):
        return name
    return "'" + name.replace("\\", "\\\\").replace("'", "\\'") + "'"


def fmu_parameters(building, effect=None):
    """{name: declared value} of every parameter an FMU of the building exposes besides forcing
    and start values: its properties (`properties`), then the added effect's `<effect>.<name>`
    (effect: (id, target) or None). A property the effect sets too (the door's
    `conductivity_factor` beside `conductivity.factor` on the door, a zone's `internal_gain` beside
    its daily gain's mean) is declared once, as the effect's parameter: two names for one number
    would leave the model undefined when both are set."""
    found = {name: p.read(building, target) for name, p, target in properties(building)}
    if effect is None:
        return found
    record = EFFECTS[effect[0]]
    own = record.read(building, effect[1])
    # the properties that move when the effect's parameters do are the effect's (two moves, so
    # that no value the effect happens to be at can hide one)
    for scale, shift in ((0.5, 0.1234567), (0.6, 0.0345678)):
        moved = record.apply(building, effect[1], {n: scale * v + shift for n, v in own.items()})
        for name, p, target in properties(building):
            if name in found and p.read(moved, target) != found[name]:
                del found[name]
    return {**found, **{f"{effect[0]}.{n}": float(v) for n, v in own.items()}}


def with_fmu_parameters(building, effect, values):
    """The building as an FMU of it (`fmu_parameters`) simulates with the parameters of `values`
    ({name: value}) set: the building file edited the same way, in one validated step."""
    names = {name: (p, target) for name, p, target in properties(building)}
    effect_values = {n.partition(".")[2]: v for n, v in values.items() if n not in names}
    unknown = [n for n in values if n not in names and (effect is None or not n.startswith(f"{effect[0]}."))]
    if unknown:
        raise KeyError(f"no FMU parameter {unknown[0]}")

    def write(data):
        for name, value in values.items():
            if name in names:
                names[name][0].write(data, names[name][1], value)
        if effect_values:
            record = EFFECTS[effect[0]]
            record.write(data, effect[1], {**record.read(building, effect[1]), **effect_values})
    return building.edited(write) if values else building
