"""The building's records: one `Building` (docs/model.md section 1), a tree of frozen records the
network is assembled from, and the quantities derived from them.

A `Building` is made by reading a building file (`building_file.py`, which validates it) and keeps
the JSON it was read from: it writes that JSON back unchanged (`to_json`), and a change to it (an
effect, `Building.edited`) is a new Building read again from the changed JSON: the records and the
file can never disagree.

Layers are listed from the INSIDE face of a component to its outside face; node ids are 1..N
(components in file order, each inside to outside, then each zone's air and radiant node, unless
the file numbers them), then the nodes zone effects add.
"""
import math
import pickle
import re
from dataclasses import dataclass, field

import numpy as np

NODE_COLUMN = re.compile(r"T([1-9][0-9]*)$")  # no leading zero: T01 is not T1
# A daily gain profile's harmonics of the day (W on cos and sin of 2 pi h tau / 24 h, tau the local
# clock time). A block schedule's harmonics fall only as 1/h and the air takes a gain to it almost
# at once, so few harmonics leave a visible error: for 150 W from 8 to 18 h in the test cell the
# validation RMSE left is 0.91 C with a constant, 0.21 C with 2 harmonics, 0.12 C with 4 (0.09 C
# with 6); 4 is where the error nears a sensor's 0.1 C noise with 9 parameters.
DAY_HARMONICS = 4
DAY_TERMS = tuple(f"{f}{h}" for h in range(1, DAY_HARMONICS + 1) for f in ("cos", "sin"))
# A workday gain (an office's, a school's) acts on the working days only, Monday to Friday of the
# site's local calendar (pandas' dayofweek 0 to 4), with its own mean and the same harmonics.
WORKDAYS = (0, 1, 2, 3, 4)
WORKDAY_TERMS = ("mean",) + DAY_TERMS


@dataclass(frozen=True)
class Material:
    conductivity: float  # W/m/K, as it conducts: the declared one times its conductivity_factor
    density: float  # kg/m3
    specific_heat: float  # J/kg/K
    name: str = field(default="", compare=False)  # its key in the file's table of materials
    conductivity_factor: float = 1.0  # -, the conductivity it has over the declared one


@dataclass(frozen=True)
class Surface:
    """A face seen by a zone: its air through h_conv, its radiant node through h_rad (W/m2/K); in
    a zone whose long-wave exchange is ScriptF, the zone's other faces by its thermal emissivity
    and its class for the view factors (docs/model.md section 3.5)."""
    zone: str
    h_conv: float
    h_rad: float
    emissivity: float = 0.9  # -, long-wave
    face_class: str | None = None  # "wall", "floor", "roof", "internal_mass"; None: from its tilt
    solar_absorptance: float | None = None  # -, of the zone's interior sun; None: not declared
    diffuse_transmittance: float = 0.0  # -, a window's of the zone's diffuse sun back out


@dataclass(frozen=True)
class Exterior:
    """Outdoor air, sky and sun (docs/model.md section 3)."""
    h_conv: float  # W/m2/K
    h_rad: float  # W/m2/K
    solar_absorptance: float  # -
    irradiance: str | None = None  # input column of the measured irradiance on the face, W/m2
    sky_view_factor: float | None = None  # part of the long-wave exchange with the sky; None: (1 + cos tilt) / 2
    convection: "OutsideConvection | None" = None  # h_conv following the wind and the face; None: h_conv constant
    longwave_emissivity: float | None = None  # h_rad following the face and the sky at this emissivity; None: constant


@dataclass(frozen=True)
class OutsideConvection:
    """An exterior face's convective coefficient computed at every step (docs/model.md section
    3.6), h_conv held in the step matrix and the rest a source lagged one step."""
    algorithm: str  # "doe2"
    roughness: float = 1.0  # DOE-2's roughness multiplier R_f (1 glass, 1.67 Rough)
    wind_factor: float = 1.0  # the face's wind over the weather station's, V_z / V_met


@dataclass(frozen=True)
class Adiabatic:
    """No flux through the face."""


@dataclass(frozen=True)
class InsideFace:
    """The face held at its component's own inside face's temperature, the heat that crosses it
    counted in no balance (EnergyPlus's InternalMass: an interzone surface that is its own
    partner; docs/model.md section 3.2)."""


@dataclass(frozen=True)
class Boundary:
    """A prescribed temperature (C, or the name of an input column) through h (W/m2/K)."""
    temperature: float | str
    h: float


@dataclass(frozen=True)
class Supply:
    flow: float  # m3/h, as declared
    temperature: float | str  # C, or an input column
    flow_factor: float = 1.0  # the flow the zone gets over the declared one (a fan off its setting)


@dataclass(frozen=True)
class Inflow:
    zone: str  # the zone the air comes from, at its air temperature
    flow: float  # m3/h


@dataclass(frozen=True)
class Lumped:
    """A node a zone effect adds (docs/model.md section 7): its capacity and its conductance to the zone."""
    capacity: float  # J/K; 0 makes the node algebraic
    conductance: float  # W/K, > 0


# An internal mass is also a face of its zone (docs/model.md section 7): its area H_m / MASS_FILM,
# TARP's coefficient of a vertical face 5 K from the air (EnergyPlus's InternalMass is vertical),
# its surface EnergyPlus's Material defaults (thermal absorptance 0.9, solar 0.7). No face holds
# less than THINNEST_MASS per m2 (some 2 mm of wood, a carpet's pile), so that a mass of no
# capacity shows no face: it is the building as declared, as the effect's neutral value must be.
MASS_FILM = 1.31 * 5.0 ** (1 / 3)  # W/m2/K
MASS_EMISSIVITY, MASS_SOLAR_ABSORPTANCE = 0.9, 0.7
THINNEST_MASS = 1000.0  # J/m2/K


def mass_area(mass):
    """m2: the face an internal mass (`Lumped`) shows its zone, its conductance over `MASS_FILM`,
    at most its capacity over `THINNEST_MASS`."""
    return min(mass.conductance / MASS_FILM, mass.capacity / THINNEST_MASS)


@dataclass(frozen=True)
class Gain:
    """A scheduled heat gain (docs/model.md section 3.4): power W times its schedule's value, the
    radiant fraction to the radiant node, the rest to the air; with a temperature slope k, plus
    k (T_air - reference_temperature) times the schedule's value, to the air."""
    name: str
    power: float  # W at a schedule value of 1 (and the air at reference_temperature)
    radiant_fraction: float = 0.0  # -
    schedule: str | None = None  # None: always 1
    temperature_slope: float = 0.0  # W/K at a schedule value of 1, <= 0
    reference_temperature: float | None = None  # C, where the power is `power`; given with a slope
    # (number, activity W a person): people whose sensible heat follows EnergyPlus's polynomial in
    # the air at each step, the power and slope above its linear part in the step matrix
    people: tuple | None = None


@dataclass(frozen=True)
class Ventilation:
    """An outdoor air flow into a zone that follows a schedule (docs/model.md section 3.4): flow
    m3/h times its schedule's value, leaving at the zone's air temperature; with `terms` (A, B,
    C, D) times max(0, A + B |T_air - T_out| + C v + D v^2), v = wind_factor times the station's
    wind (m/s), and with `controls` only while they hold (section 3.6)."""
    name: str
    flow: float  # m3/h at a schedule value of 1
    schedule: str | None = None  # None: always 1
    terms: tuple | None = None  # (A -, B 1/K, C s/m, D s2/m2); None: the flow times its schedule alone
    wind_factor: float = 1.0  # v / V_met: the station's wind at the zone's height
    # (minimum indoor C, maximum indoor C, delta T_air - T_out K, minimum outdoor C, maximum
    # outdoor C, maximum wind m/s at the zone's height), -inf or inf where not declared; None: none
    controls: tuple | None = None

    @property
    def followed(self):
        """Whether the flow follows the state or the wind (its terms or controls declared)."""
        return self.terms is not None or self.controls is not None

    @property
    def reads_wind(self):
        """Whether the flow follows the wind: a velocity term, or a maximum wind speed."""
        return bool(self.terms is not None and (self.terms[2] or self.terms[3])
                    or self.controls is not None and math.isfinite(self.controls[5]))


@dataclass(frozen=True)
class AngularTransmittance:
    """A glazing's transmittance relative to its normal-incidence one (docs/model.md section 4.1):
    factors at angles of incidence (deg, increasing from 0, factor 1 at 0) for the direct sun, and
    one factor for the diffuse sky and ground."""
    angles: tuple  # deg
    factors: tuple  # -
    diffuse: float  # -


@dataclass(frozen=True)
class AngularAbsorptance:
    """The sun a glazing's panes absorb with the angle of incidence (docs/model.md section 4.1),
    relative to its normal-incidence absorptance, on each side: the outer panes' (its outside
    face's `solar_absorptance`) and the inner panes' (`inner_solar_absorptance`), factors at
    angles of incidence (deg, increasing from 0, factor 1 at 0) for the direct sun and one factor
    for the diffuse sky and ground."""
    angles: tuple  # deg
    outside: tuple  # -
    outside_diffuse: float  # -
    inside: tuple  # -
    inside_diffuse: float  # -

    def table(self, side):
        """(angles, factors, diffuse) of `side`, "outside" or "inside", as
        `model.solar.transmitted_irradiance` reads a table."""
        return self.angles, getattr(self, side), getattr(self, f"{side}_diffuse")


@dataclass(frozen=True)
class WindowGap:
    """A window's gas gap (docs/model.md section 4.1): the index of its layer among the component's
    (from 0 at the inside face), the emissivities of the two panes' faces across it and its gas
    as `model.glazing.gas_properties` reads it."""
    layer: int
    emissivities: tuple  # (-, -)
    gas: object


@dataclass(frozen=True)
class Window:
    """A component solved as EnergyPlus solves a window's panes (docs/model.md section 4.1): its
    gaps' conductances follow the panes' temperatures, and its inside face takes ISO 15099's
    convection where its zone's inside algorithm is TARP. height in m."""
    height: float
    gaps: tuple = ()  # WindowGap, ...


@dataclass(frozen=True)
class ShadingSurface:
    """An opaque polygon ((x, y, z) m) that shades the exterior faces it names (docs/model.md 4.2)."""
    name: str
    vertices: tuple
    faces: tuple  # component names


@dataclass(frozen=True)
class Zone:
    name: str
    volume: float  # m3
    air_node: int
    radiant_node: int
    air_change_rate: float = 0.0  # 1/h
    internal_gain: float = 0.0  # W
    heat_input: tuple = ()  # input columns, W, summed
    heat_input_radiative_fraction: float = 0.0  # part of the heat input given to the radiant node
    supply: Supply | None = None
    airflow_from: tuple = ()  # Inflow records
    thermal_bridges: tuple = ()  # (to, UA W/K): "outdoor" or an input column of a temperature
    convection_factor: float = 1.0  # scale on the inside h_conv of the surfaces facing the zone
    occupied: bool | None = None  # None: not declared
    daily_gain: tuple = ()  # (term of DAY_TERMS, W) for every term when declared; () not declared
    workday_gain: tuple = ()  # (term of WORKDAY_TERMS, W) on working days only; () not declared
    proportional_gains: tuple = ()  # (input column, k in W per unit of the column)
    internal_mass: Lumped | None = None  # furniture and undeclared mass, coupled to the air
    heat_input_lag: Lumped | None = None  # the heater's own capacity, between heat input and zone
    envelope_factor: float = 1.0  # scale on the layer conductances of the zone's components to outside
    shading_transmittance: float = 0.0  # part of its glazings' sun a closed shading still lets in
    heat_input_factor: float = 1.0  # the heat its heat input columns deliver, per W they read
    air_exchange: tuple = ()  # (other zone, m3/h each way): air through an open internal door
    gains: tuple = ()  # Gain records
    ventilation: tuple = ()  # Ventilation records
    longwave: str = "radiant_node"  # "radiant_node" (the star node) or "scriptf" (docs/model.md 3.5)
    view_factors: tuple = ()  # (from component, to component, F) declared for "scriptf"; () approximated
    longwave_followed: bool = False  # "scriptf" at the faces' temperatures of each step, not at 20 C
    mass_node: int | None = None  # ids of the nodes those two add (docs/model.md section 7)
    heater_node: int | None = None
    inside_convection_algorithm: str = "simple"  # "simple": h_conv constant; "tarp": followed step by step


def traced_input(window, face):
    """The input of the direct sun `window` lets in that falls on `face` (docs/model.md 4.1)."""
    return f"Itb_{window}@{face}"


@dataclass(frozen=True)
class Component:
    name: str
    area: float  # m2
    tilt: float  # degrees from horizontal, 0 = facing up
    azimuth: float  # degrees clockwise from north
    layers: tuple  # ((Material, thickness m), ...) from the inside face outwards
    node_ids: tuple  # ids, ordered by depth
    depths: tuple  # m from the inside face
    inside: Surface
    outside: Exterior | Adiabatic | Surface | Boundary | InsideFace
    solar_transmittance: float | None = None
    transmitted_solar_to: str | None = None
    shading: str | None = None  # input column in 0..1 multiplying the transmittance
    conductivity_factor: float = 1.0  # scale on the conductances between its nodes
    capacity_factor: float = 1.0  # scale on the heat capacities of its nodes
    angular: AngularTransmittance | None = None  # the transmittance with the angle of incidence
    solar_distribution: tuple = ()  # (component, fraction) of the transmitted sun; () all to transmitted_solar_to
    inner_solar_absorptance: float = 0.0  # part of the sun on the outside face absorbed at the inside face
    angular_absorptance: AngularAbsorptance | None = None  # the panes' absorptance with the angle of incidence
    vertices: tuple | None = None  # the outside face's polygon ((x, y, z) m, counterclockwise from outside)
    holes: tuple = ()  # polygons cut out of it (its windows), m
    diffuse_distribution: tuple = ()  # (component, fraction) of the transmitted diffuse sun; () as the direct
    window: Window | None = None  # its panes' gaps and inside face as EnergyPlus's window heat balance
    traced_beam: tuple = ()  # (face, ((component, fraction), ...)): its direct sun traced onto each face, its split there

    @property
    def receivers(self):
        """((component, fraction), ...) of the sun a glazing lets in: its `solar_distribution`, or
        all of it to `transmitted_solar_to`; () for an opaque component."""
        if self.solar_transmittance is None:
            return ()
        return self.solar_distribution or ((self.transmitted_solar_to, 1.0),)

    @property
    def sun_inputs(self):
        """((input name, receivers), ...): the inputs of the sun a glazing lets in and the split of
        each (docs/model.md section 4.1). One input split by `receivers`; where the glazing declares
        a `diffuse_distribution`, its direct sun `Itb_<component>` split by `receivers` and its
        diffuse sun `Itd_<component>` by the diffuse distribution; where it also traces its direct
        sun (`traced_beam`), the part that falls on each face, `Itb_<component>@<face>`, split as
        the face's entry says, and `Itb_<component>` the part that falls on none. () for an opaque
        component."""
        if self.solar_transmittance is None:
            return ()
        if not self.diffuse_distribution:
            return ((self.transmitted_input, self.receivers),)
        return ((f"Itb_{self.name}", self.receivers), (f"Itd_{self.name}", self.diffuse_distribution),
                *((traced_input(self.name, face), split) for face, split in self.traced_beam))

    @property
    def sun_receivers(self):
        """Names of the components on which the sun a glazing lets in lands, direct or diffuse."""
        return tuple(dict.fromkeys(name for _, receivers in self.sun_inputs for name, _ in receivers))

    @property
    def transmitted_input(self):
        """Name of the input of the sun a glazing lets in (W/m2 of glazing, before its normal
        transmittance): `It_<component>` where its transmittance varies with the angle of
        incidence, else its face's irradiance input."""
        if self.angular is None:
            return self.irradiance_input
        return f"It_{self.name}"

    def absorbed_input(self, side):
        """Name of the input of the sun the panes of `side` ("outside" or "inside") absorb (W/m2
        of glazing, before their normal-incidence absorptance): `Iao_<component>` or
        `Iai_<component>` where the glazing declares an `angular_absorptance`, else its face's
        irradiance input."""
        if self.angular_absorptance is None:
            return self.irradiance_input
        return f"Ia{side[0]}_{self.name}"

    @property
    def absorbed_inputs(self):
        """((input name, side), ...) of an `angular_absorptance`; () without one."""
        if self.angular_absorptance is None:
            return ()
        return tuple((self.absorbed_input(side), side) for side in ("outside", "inside"))

    @property
    def thickness(self):
        """Total thickness of the layers (m)."""
        return sum(t for _, t in self.layers)

    @property
    def irradiance_input(self):
        """Name of the input holding the irradiance on the outside face (W/m2): the face's
        measured column if it names one, else `I_<component>`; None if the face is not exterior."""
        if not isinstance(self.outside, Exterior):
            return None
        return self.outside.irradiance or f"I_{self.name}"


@dataclass(frozen=True)
class Building:
    name: str
    # latitude, longitude (deg), altitude (m), timezone, ground_albedo; if declared, ground_temperature (C), sky_diffuse,
    # flow_density, solar_position
    site: dict
    zones: tuple
    components: tuple
    sensors: dict = field(default_factory=dict)  # sensor name -> node id
    flux_sensors: dict = field(default_factory=dict)  # sensor name -> (component, "inside" or "outside")
    boundary_factors: dict = field(default_factory=dict)  # boundary column -> factor on its conductances
    schedules: dict = field(default_factory=dict)  # name -> Schedule
    shading: tuple = ()  # ShadingSurface records
    constructions: dict = field(default_factory=dict)  # construction name -> names of the components built of it
    source: str = field(default="<building>", compare=False)
    data: dict = field(default_factory=dict, compare=False, repr=False)  # the JSON it was read from
    # what reads an edit again, (data, source=, edited_from=) -> Building: `building_file.parse_building`,
    # given by the reader itself so that the records import nothing of it
    reader: object = field(default=None, compare=False, repr=False)

    @property
    def n_nodes(self):
        return self.own_nodes + len(self.added_nodes)

    @property
    def own_nodes(self):
        """The number of nodes of its components and zones (ids 1..own_nodes); the nodes its
        effects add follow them."""
        return sum(len(c.node_ids) for c in self.components) + 2 * len(self.zones)

    @property
    def added_nodes(self):
        """{id: (zone name, what)} of the nodes zone effects add after the building's own (an
        internal mass, a heater's capacity), which no sensor measures."""
        added = {}
        for z in self.zones:
            if z.mass_node is not None:
                added[z.mass_node] = (z.name, "internal mass")
            if z.heater_node is not None:
                added[z.heater_node] = (z.name, "heater")
        return dict(sorted(added.items()))

    @property
    def exterior_components(self):
        """Components whose outside face sees the outdoor air, sky and sun."""
        return tuple(c for c in self.components if isinstance(c.outside, Exterior))

    @property
    def followed_coefficients(self):
        """(where, field) of each zone and exterior face whose convective or long-wave coefficient
        follows the temperatures or the wind (docs/model.md section 3.6)."""
        return (tuple((f"zone {z.name}", "inside_convection_algorithm") for z in self.zones
                      if z.inside_convection_algorithm != "simple")
                + tuple((f"zone {z.name}", "longwave_followed") for z in self.zones if z.longwave_followed)
                + ((("site", "flow_density"),) if self.site.get("flow_density") == "outdoor" else ())
                + tuple((f"component {c.name}", "outside.convection") for c in self.exterior_components
                        if c.outside.convection is not None)
                + tuple((f"component {c.name}", "outside.longwave") for c in self.exterior_components
                        if c.outside.longwave_emissivity is not None)
                + tuple((f"component {c.name}", "window") for c in self.components if c.window is not None)
                + tuple((f"zone {z.name}", f"gains {g.name}.people") for z in self.zones for g in z.gains if g.people)
                + tuple((f"zone {z.name}", f"ventilation {v.name}") for z in self.zones for v in z.ventilation
                        if v.followed))

    @property
    def reads_wind(self):
        """Where the building reads the weather's wind: the first exterior face whose convection
        follows it, else the first air flow that does ("zone's ventilation name"); None: nowhere."""
        faces = [f"component {c.name}" for c in self.exterior_components if c.outside.convection is not None]
        flows = [f"zone {z.name}'s ventilation {v.name}" for z in self.zones for v in z.ventilation if v.reads_wind]
        return next(iter(faces + flows), None)

    @property
    def input_columns(self):
        """Names of the measured input columns the building refers to (heat inputs, supply and
        boundary temperatures, measured irradiance, shading), in order of appearance."""
        names = []
        for z in self.zones:
            names += z.heat_input
            if z.supply is not None and isinstance(z.supply.temperature, str):
                names.append(z.supply.temperature)
            names += [to for to, _ in z.thermal_bridges if to != "outdoor"]
        for c in self.components:
            if isinstance(c.outside, Boundary) and isinstance(c.outside.temperature, str):
                names.append(c.outside.temperature)
            if isinstance(c.outside, Exterior) and c.outside.irradiance:
                names.append(c.outside.irradiance)
            if c.shading:
                names.append(c.shading)
        return tuple(n for n in dict.fromkeys(names) if n not in self.schedules)

    @property
    def switched(self):
        """"zone's ventilation (or gain) name" of each air flow and gain whose conductance follows a
        varying schedule (`Network.switched`): the network's matrix then changes in time."""
        varying = lambda name: name is not None and not self.schedules[name].is_constant  # noqa: E731
        return tuple(f"{z.name}'s ventilation {v.name}" for z in self.zones for v in z.ventilation
                     if varying(v.schedule)) + tuple(f"{z.name}'s gain {g.name}" for z in self.zones for g in z.gains
                                                     if g.temperature_slope and varying(g.schedule))

    @property
    def schedule_inputs(self):
        """Names of the schedules the network reads as inputs (the non-constant ones its gains and
        boundary temperatures use), in order of appearance; their values come from the file."""
        names = [g.schedule for z in self.zones for g in z.gains + z.ventilation if g.schedule is not None]
        names += [c.outside.temperature for c in self.components
                  if isinstance(c.outside, Boundary) and isinstance(c.outside.temperature, str)]
        return tuple(n for n in dict.fromkeys(names) if n in self.schedules and not self.schedules[n].is_constant)

    @property
    def boundary_columns(self):
        """The input columns of boundary temperatures (attic, cellar, a neighbour): those a
        component's outside face or a zone's thermal bridge sees, in order of appearance."""
        return boundary_columns(self.zones, self.components)

    def boundary_factor(self, column):
        """The factor on every conductance from the building to a boundary column (1 if not declared)."""
        return self.boundary_factors.get(column, 1.0)

    def zone(self, name):
        return next(z for z in self.zones if z.name == name)

    def shades_of(self, component_name):
        """The polygons of the shading surfaces that name a component among their faces."""
        return tuple(s.vertices for s in self.shading if component_name in s.faces)

    def component(self, name):
        return next(c for c in self.components if c.name == name)

    def _faces(self, zone_name):
        """[(component, its Surface toward the zone, that face's node id)]: the inside faces of
        the zone's components, then the outside faces of partitions toward it."""
        faces = [(c, c.inside, c.node_ids[0]) for c in self.components if c.inside.zone == zone_name]
        faces += [(c, c.outside, c.node_ids[-1]) for c in self.components
                  if isinstance(c.outside, Surface) and c.outside.zone == zone_name]
        return faces

    def enclosure(self, zone_name):
        """The faces of a zone's enclosure, for its long-wave exchange: (names, node ids, areas m2,
        emissivities, tilts deg, azimuths deg, classes), each face's tilt and azimuth those of its
        normal away from the zone (a partition's outside face turned round)."""
        faces = self._faces(zone_name)
        turned = [side is not c.inside for c, side, _ in faces]
        return (tuple(c.name for c, _, _ in faces), tuple(i for _, _, i in faces),
                tuple(c.area for c, _, _ in faces), tuple(side.emissivity for _, side, _ in faces),
                tuple(180.0 - c.tilt if t else c.tilt for (c, _, _), t in zip(faces, turned)),
                tuple((c.azimuth + 180.0) % 360.0 if t else c.azimuth for (c, _, _), t in zip(faces, turned)),
                tuple(side.face_class for _, side, _ in faces))

    def interior_solar(self, zone_name):
        """(names, areas m2, absorptances, diffuse transmittances back out) of the components that
        face a zone, for its interior sun (`model.interior_sun`): a component's faces in the zone
        summed, their absorptances weighed by area; None unless every face declares its
        solar_absorptance."""
        faces = self._faces(zone_name)
        if any(side.solar_absorptance is None for _, side, _ in faces):
            return None
        names = tuple(dict.fromkeys(c.name for c, _, _ in faces))
        area, alpha, tau = (np.zeros(len(names)) for _ in range(3))
        for c, side, _ in faces:
            k = names.index(c.name)
            area[k] += c.area
            alpha[k] += c.area * side.solar_absorptance
            tau[k] += c.area * side.diffuse_transmittance
        return names, area, alpha / area, tau / area

    def facing(self, zone_name):
        """Ids of the surface nodes that face a zone (inside faces, and outside faces of partitions)."""
        return tuple(i for _, _, i in self._faces(zone_name))

    def mean_inside_convection(self, zone_name):
        """The area-weighted mean of the declared convective coefficients h_conv of the surfaces
        facing a zone, W/m2/K, before its `convection_factor`."""
        faces = self._faces(zone_name)
        return sum(c.area * side.h_conv for c, side, _ in faces) / sum(c.area for c, _, _ in faces)

    def node_names(self):
        """{id: readable name}: "<component> at <depth> m", "<zone> air", "<zone> radiant"."""
        names = {}
        for c in self.components:
            for i, depth in zip(c.node_ids, c.depths):
                names[i] = f"{c.name} at {depth:.3f} m"
        for z in self.zones:
            names[z.air_node] = f"{z.name} air"
            names[z.radiant_node] = f"{z.name} radiant"
        for i, (zone, what) in self.added_nodes.items():
            names[i] = f"{zone} {what}"
        return dict(sorted(names.items()))

    def node_of(self, column):
        """The node id a measurement column names (`T<id>` or a sensor), or None."""
        match = NODE_COLUMN.match(str(column))
        if match:
            return int(match.group(1))
        return self.sensors.get(column)

    def to_json(self):
        """The building file's JSON content (a copy): exactly what it was read from."""
        return json_copy(self.data)

    def edited(self, change):
        """A new Building from this one's JSON changed in place by `change(data)`, read again
        (validated: its JSON Schema, then the rules it cannot state)."""
        data = self.to_json()
        change(data)
        return self.reader(data, source=self.source, edited_from=self.data)


def json_copy(data):
    """A deep copy of a building file's JSON content. Through pickle, which copies dicts, lists
    and numbers five times faster than copy.deepcopy: an effect's edit copies the file twice at
    every simulation of a calibration."""
    return pickle.loads(pickle.dumps(data, pickle.HIGHEST_PROTOCOL))


def boundary_columns(zones, components):
    """`Building.boundary_columns` of these zones and components."""
    names = [c.outside.temperature for c in components
             if isinstance(c.outside, Boundary) and isinstance(c.outside.temperature, str)]
    names += [to for z in zones for to, _ in z.thermal_bridges if to != "outdoor"]
    return tuple(dict.fromkeys(names))

