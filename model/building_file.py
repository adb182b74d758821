"""Read and validate a building file (`"format": "nodal-building/1"`, docs/model.md section 1) into
the building's records (`building.py`).

Two checks, each rule in one of them, each failure an `InputError` naming the file and the field:
the format's JSON Schema (`data/nodal-building.schema.json`: every field's type, whether it is
required, its range, its allowed values, which fields go together, and no unknown field, so that
a misspelt optional field is refused instead of silently defaulted), then by hand what a schema
cannot say: the names one part gives of another (a layer's material, a face's zone, a window's
receiving component, a schedule, a sensor's component), node ids 1..N with no gap, node depths
within their component, schedules' hours and dates in order, fractions that add up.

Nodes are given explicitly (`"nodes": [{"id", "depth"}]`) or generated from the layers
(`"nodes": {"max_spacing": m}`), in which case the tool numbers every node: components in file
order, each inside to outside, then each zone's air and radiant node.
"""
import functools
import json
import math
from dataclasses import replace
from importlib.resources import files

import numpy as np

from .building import (DAY_TERMS, WORKDAY_TERMS, Adiabatic, AngularAbsorptance, AngularTransmittance, Boundary, Building, Component,
                       Exterior, Gain, Inflow, InsideFace, Lumped, Material, OutsideConvection, ShadingSurface, Supply, Surface,
                       Ventilation, Window, WindowGap, Zone, boundary_columns, json_copy)
from . import geometry
from .discretise import generated_depths
from .errors import InputError
from .glazing import GASES
from .schedule import WEEKDAYS, Schedule

# Depths are given in metres with a few decimals; a node "at" the outside face may be
# off by rounding only.
DEPTH_TOLERANCE = 1e-9
# A sensor's depth names the node nearest it within this distance (m): positions in a building
# description are rounded to the millimetre.
SENSOR_TOLERANCE = 1e-3
# read when the module is: the FMU's copy of this package may be imported from a folder that is gone
# by the time an importer's parameters edit the building
SCHEMA = json.loads(files(__package__).joinpath("data/nodal-building.schema.json").read_text(encoding="utf-8"))


def schema_default(definition, *path):
    """The default the JSON Schema gives an optional field, the only place it is written: the
    field `path` of one of its definitions ("site", "altitude"; "zone", "supply", "flow_factor";
    "zone", "gains", "radiant_fraction" for a field of each item of a list)."""
    node = SCHEMA["$defs"][definition]
    for name in path:
        node = node.get("items", node)["properties"][name]
    return node["default"]


def load_building(path):
    """Read and validate a building file (`parse_building`); return a `Building`."""
    try:
        with open(path, encoding="utf-8") as f:
            data = json.load(f)
    except FileNotFoundError:
        raise InputError(path, "file", "not found") from None
    except json.JSONDecodeError as e:
        raise InputError(path, f"line {e.lineno}", f"not valid JSON ({e.msg})") from None
    return parse_building(data, source=str(path))


def parse_building(data, source="<building>", edited_from=None):
    """Validate a building description already parsed from JSON (the schema, then the rules it
    cannot state); return a `Building`. `edited_from`: the description `data` is an edit of, which
    follows the schema already (`Building.edited`)."""
    check_schema(data, source, edited_from)
    return parse_checked(data, source)


def check_schema(data, source, edited_from=None):
    """InputError naming the field where `data` does not follow the format's JSON Schema; of an
    edit of `edited_from` (which does), the zones and components the edit changed, where it
    changed nothing else: an effect's edit, read again at each step of a calibration."""
    prefix, error = _schema_error(data, edited_from)
    if error is not None:
        where = "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in (*prefix, *error.absolute_path))
        where = where.lstrip(".")
        path = list(error.absolute_schema_path)
        if "propertyNames" in path:  # a key at fault: name it
            where = f"{where}.{error.instance}".lstrip(".")
        problem = error.message
        if error.validator in ("oneOf", "anyOf", "not") and "description" in error.schema:
            # jsonschema's words for these quote the schema: its description says the rule instead
            problem = (f"fits none of its forms. {error.schema['description']}" if error.validator != "not"
                       else error.schema["description"])
        if "dependentSchemas" in path:  # a rule of which fields go together: name the field asking
            problem += f" (with {path[path.index('dependentSchemas') + 1]})"
        raise InputError(source, where or "(top level)", problem)


# the lists whose items an edit may change alone, and the schema's definition of an item
ITEMS = {"zones": "zone", "components": "component"}


def _schema_error(data, before):
    """(path prefix, jsonschema's best error or None) of `data`, or, of an edit of `before` that
    removed no field, of the top-level fields it added or changed, and within those of ITEMS of
    the same length, of the items it changed: the top level of the schema asks nothing of a
    field but its own schema (its properties, none required but those `before` has, no other)."""
    import jsonschema  # here: an FMU at its declared parameters runs this module without it
    best = jsonschema.exceptions.best_match
    if (not isinstance(data, dict) or not isinstance(before, dict) or not before.keys() <= data.keys()
            or not data.keys() <= SCHEMA["properties"].keys()):
        return (), best(_validator(None).iter_errors(data))
    for key, value in data.items():
        if key in before and value == before[key]:
            continue
        old = before.get(key)
        if key in ITEMS and isinstance(value, list) and isinstance(old, list) and len(value) == len(old):
            for i, (new, was) in enumerate(zip(value, old)):
                error = best(_validator(ITEMS[key]).iter_errors(new)) if new != was else None
                if error is not None:
                    return (key, i), error
            continue
        error = best(_validator(("properties", key)).iter_errors(value))
        if error is not None:
            return (key,), error
    return (), None


@functools.lru_cache(maxsize=None)
def _validator(definition):
    """The format's JSON Schema validator, of a whole file, of one of its `$defs` (a name) or of
    a top-level field (("properties", name)), its references inlined (`_inlined`). Python's json
    reads NaN and Infinity, which JSON has no number for, and an id 1.0 is a float the parser
    cannot index by: a "number" is a finite one and an "integer" an int here."""
    import jsonschema
    base = jsonschema.Draft202012Validator
    types = base.TYPE_CHECKER.redefine_many({
        "number": lambda _, v: isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v),
        "integer": lambda _, v: isinstance(v, int) and not isinstance(v, bool)})
    if definition is None:
        schema = {k: v for k, v in SCHEMA.items() if k != "$defs"}
    elif isinstance(definition, tuple):  # a top-level field's own schema
        schema = SCHEMA["properties"][definition[1]]
    else:
        schema = SCHEMA["$defs"][definition]
    return jsonschema.validators.extend(base, type_checker=types)(_inlined(schema, SCHEMA["$defs"]))


def _inlined(schema, definitions):
    """`schema` with every `{"$ref": "#/$defs/name"}` replaced by that definition (inlined too;
    none refers to itself), one with annotations beside it by `allOf` of the definition, so
    that an error's schema is the definition's as through the reference: jsonschema resolves
    a reference at every visit, some 60 % of the check of a component, which an effect's edit
    makes at each step of a calibration."""
    if isinstance(schema, list):
        return [_inlined(s, definitions) for s in schema]
    if not isinstance(schema, dict):
        return schema
    inlined = {k: _inlined(v, definitions) for k, v in schema.items() if k != "$ref"}
    if "$ref" not in schema:
        return inlined
    target = _inlined(definitions[schema["$ref"].removeprefix("#/$defs/")], definitions)
    return {**inlined, "allOf": [*inlined.get("allOf", ()), target]} if inlined else target


def parse_checked(data, source="<building>"):
    """The `Building` of a description that follows the JSON Schema, with the rules the schema
    cannot state checked; an edit of it is read by `parse_building`, the schema first. The FMU
    reads its own copy of a file `parse_building` read this way (with its declared parameters its
    host needs numpy only); anything else reads through `parse_building`."""
    check = _Checker(source)
    site = data["site"]
    site = {"latitude": float(site["latitude"]), "longitude": float(site["longitude"]),
            "altitude": float(site.get("altitude", schema_default("site", "altitude"))),
            "timezone": site.get("timezone", schema_default("site", "timezone")),
            "ground_albedo": float(site.get("ground_albedo", schema_default("site", "ground_albedo"))),
            "air_density": float(site.get("air_density", schema_default("site", "air_density")))}
    if "ground_temperature" in data["site"]:
        site["ground_temperature"] = float(data["site"]["ground_temperature"])
    for field in ("sky_diffuse", "flow_density", "solar_position"):
        if field in data["site"]:
            site[field] = data["site"][field]
    schedules = {name: _schedule(check, name, s, f"schedules.{name}") for name, s in data.get("schedules", {}).items()}
    materials = {name: _material(name, m) for name, m in data["materials"].items()}
    raw_zones, raw_components = data["zones"], data["components"]
    zone_names = [z["name"] for z in raw_zones]
    check.unique(zone_names, "zones", "zone name")
    raw_sensors = data.get("sensors", {})
    sensor_depths = _sensor_depths(check, raw_sensors, raw_components)
    components = [_component(check, c, f"components[{i}]", materials, zone_names, sensor_depths)
                  for i, c in enumerate(raw_components)]
    check.unique([c["name"] for c in components], "components", "component name")
    explicit = _explicit_ids(check, raw_zones, components)
    next_id = iter(range(1, 10 ** 9))
    if not explicit:
        for c in components:
            c["node_ids"] = tuple(next(next_id) for _ in c["depths"])
    zones = tuple(_zone(check, z, f"zones[{i}]", zone_names, explicit, next_id, schedules)
                  for i, z in enumerate(raw_zones))
    components = tuple(Component(**c) for c in components)
    by_name = {c.name: c for c in components}
    names = set(by_name)
    for i, c in enumerate(components):
        if c.transmitted_solar_to is not None and c.transmitted_solar_to not in names:
            check.fail(f"components[{i}].transmitted_solar_to",
                       f"names no component ({c.transmitted_solar_to!r})")
        for field, fractions in (("solar_distribution", c.solar_distribution),
                                 ("diffuse_distribution", c.diffuse_distribution)):
            for name, _ in fractions:
                if name not in names:
                    check.fail(f"components[{i}].{field}.{name}", f"names no component ({name!r})")
        _check_traced_beam(check, f"components[{i}]", c, by_name)
    _check_proportional_columns(check, zones, components)
    _check_air_exchanges(check, zones)
    _check_view_factors(check, zones, components)
    boundary_factors = _boundary_factors(check, data, zones, components)
    _check_node_ids(check, zones, components)
    zones = _number_added_nodes(zones, sum(len(c.node_ids) for c in components) + 2 * len(zones))
    constructions = _constructions(check, data, components)
    flux_sensors = {name: (raw["component"], raw["face"]) for name, raw in raw_sensors.items()
                    if raw.get("quantity") == "heat_flux"}
    sensors = {name: _sensor_node(check, name, raw, zones, components) for name, raw in raw_sensors.items()
               if name not in flux_sensors}
    return Building(name=str(data.get("name", "")), site=site, zones=zones, components=components,
                    sensors=sensors, flux_sensors=flux_sensors, boundary_factors=boundary_factors,
                    schedules=schedules, shading=_shading(check, data, components), constructions=constructions,
                    source=source, data=json_copy(data),
                    reader=parse_building)


class _Checker:
    """Fails with the file and the field path."""

    def __init__(self, source):
        self.source = source

    def fail(self, where, problem):
        raise InputError(self.source, where, problem)

    def unique(self, values, where, what):
        seen = set()
        for v in values:
            if v in seen:
                self.fail(where, f"{what} {v!r} appears twice")
            seen.add(v)


def _material(name, raw):
    """A `Material` of the file's table, conducting its conductivity (W/m/K) times its
    `conductivity_factor` (the default 1 leaves it as written, to the bit)."""
    factor = float(raw.get("conductivity_factor", schema_default("material", "conductivity_factor")))
    return Material(conductivity=float(raw["conductivity"]) * factor, density=float(raw["density"]),
                    specific_heat=float(raw["specific_heat"]), name=name, conductivity_factor=factor)


def _constructions(check, data, components):
    """{construction: (component, ...)} of `constructions`: each names components of the file, a
    component in one construction at most."""
    names, owner = {c.name for c in components}, {}
    for construction, members in data.get("constructions", {}).items():
        for k, name in enumerate(members):
            where = f"constructions.{construction}[{k}]"
            if name not in names:
                check.fail(where, f"names no component ({name!r})")
            if name in owner:
                check.fail(where, f"{name!r} is built of {owner[name]!r} already: a component has one construction")
            owner[name] = construction
    return {construction: tuple(members) for construction, members in data.get("constructions", {}).items()}


def _increasing(values):
    return all(b > a for a, b in zip(values, values[1:]))


def _schedule(check, name, raw, where):
    if "constant" in raw:
        return Schedule(name=name, constant=float(raw["constant"]))
    days = raw["days"]
    profiles = []
    for profile, pairs in days.items():
        untils = [u for u, _ in pairs]
        if not _increasing(untils) or untils[-1] != 24:
            check.fail(f"{where}.days.{profile}", "the hours until which each value holds must increase and end at 24")
        profiles.append((profile, tuple((float(u), float(v)) for u, v in pairs)))
    periods, last = [], 0
    for k, period in enumerate(raw["periods"]):
        pw = f"{where}.periods[{k}]"
        month, day = (int(part) for part in period["through"].split("-"))
        if month * 100 + day <= last:
            check.fail(f"{pw}.through", "the periods' dates must increase")
        last = month * 100 + day
        for d, profile in zip(WEEKDAYS, period["week"]):
            if profile not in days:
                check.fail(f"{pw}.week", f"{d}: names no profile of days ({profile!r})")
        periods.append(((month, day), tuple(period["week"])))
    if last != 1231:
        check.fail(f"{where}.periods", "the last period must run through 12-31")
    return Schedule(name=name, days=tuple(profiles), periods=tuple(periods))


def _schedule_of(check, item, where, schedules):
    """The name of the schedule `item` follows (None: constant), checked to be one of the file's."""
    schedule = item.get("schedule")
    if schedule is not None and schedule not in schedules:
        check.fail(f"{where}.schedule", f"names no schedule of the file ({schedule!r})")
    return schedule


def _gains(check, z, where, schedules):
    gains = []
    for k, g in enumerate(z.get("gains", ())):
        gw = f"{where}.gains[{k}]"
        schedule = _schedule_of(check, g, gw, schedules)
        slope = float(g.get("temperature_slope", schema_default("zone", "gains", "temperature_slope")))
        if slope and "reference_temperature" not in g:
            check.fail(f"{gw}.reference_temperature", "is required with a temperature_slope")
        if slope and schedule is not None and _negative(schedules[schedule]):
            check.fail(f"{gw}.schedule", f"{schedule!r} takes negative values: with a temperature_slope it is >= 0")
        people = g.get("people")
        if people is not None and schedule is not None and _negative(schedules[schedule]):
            check.fail(f"{gw}.schedule", f"{schedule!r} takes negative values: a number of people is >= 0")
        gains.append(Gain(name=g["name"], power=float(g["power"]),
                          radiant_fraction=float(g.get("radiant_fraction",
                                                       schema_default("zone", "gains", "radiant_fraction"))),
                          schedule=schedule, temperature_slope=slope,
                          reference_temperature=float(g["reference_temperature"]) if slope else None,
                          people=None if people is None else (float(people["number"]), float(people["activity"]))))
    return tuple(gains)


def _negative(schedule):
    """Whether a schedule takes a value below 0 (a conductance it multiplies would be negative)."""
    values = [schedule.constant] if schedule.constant is not None else [v for _, p in schedule.days for _, v in p]
    return min(values) < 0


def _ventilation(check, z, where, schedules):
    flows = []
    for k, v in enumerate(z.get("ventilation", ())):
        vw = f"{where}.ventilation[{k}]"
        schedule = _schedule_of(check, v, vw, schedules)
        if schedule is not None and not schedules[schedule].is_constant and _negative(schedules[schedule]):
            check.fail(f"{vw}.schedule", f"{schedule!r} takes negative values: an air flow is >= 0")
        controls = v.get("controls")
        if controls is not None:
            limits = tuple(float(controls.get(f, default)) for f, default in CONTROLS)
            for low, high in (("minimum_indoor_temperature", "maximum_indoor_temperature"),
                              ("minimum_outdoor_temperature", "maximum_outdoor_temperature")):
                if low in controls and high in controls and controls[low] > controls[high]:
                    check.fail(f"{vw}.controls.{low}", f"{controls[low]:g} C is above the {high} "
                               f"({controls[high]:g} C): the flow would never run")
        terms = v.get("terms")
        flows.append(Ventilation(name=v["name"], flow=float(v["flow"]), schedule=schedule,
                                 terms=None if terms is None else tuple(float(t) for t in terms),
                                 wind_factor=float(v.get("wind_factor", 1.0)),
                                 controls=None if controls is None else limits))
    return tuple(flows)


# a ventilation's controls in `Ventilation.controls`'s order, each with the value at which it does not act
CONTROLS = (("minimum_indoor_temperature", -math.inf), ("maximum_indoor_temperature", math.inf),
            ("delta_temperature", -math.inf), ("minimum_outdoor_temperature", -math.inf),
            ("maximum_outdoor_temperature", math.inf), ("maximum_wind_speed", math.inf))


def _angular(check, c, where):
    raw = c.get("angular_transmittance")
    if raw is None:
        return None
    where = f"{where}.angular_transmittance"
    angles, factors = [float(a) for a in raw["angles"]], [float(f) for f in raw["factors"]]
    if len(angles) != len(factors):
        check.fail(where, "angles and factors must be lists of one length")
    if angles[0] != 0 or not _increasing(angles):
        check.fail(f"{where}.angles", "must start at 0 and increase")
    return AngularTransmittance(angles=tuple(angles), factors=tuple(factors), diffuse=float(raw["diffuse"]))


def _angular_absorptance(check, c, where):
    raw = c.get("angular_absorptance")
    if raw is None:
        return None
    where = f"{where}.angular_absorptance"
    angles = [float(a) for a in raw["angles"]]
    if angles[0] != 0 or not _increasing(angles):
        check.fail(f"{where}.angles", "must start at 0 and increase")
    sides = {side: [float(f) for f in raw[side]] for side in ("outside", "inside")}
    for side, factors in sides.items():
        if len(factors) != len(angles):
            check.fail(f"{where}.{side}", f"has {len(factors)} factors for {len(angles)} angles")
    return AngularAbsorptance(angles=tuple(angles), outside=tuple(sides["outside"]),
                              outside_diffuse=float(raw["outside_diffuse"]), inside=tuple(sides["inside"]),
                              inside_diffuse=float(raw["inside_diffuse"]))


def _zone_value(z, name):
    """A zone's number `name` as its description gives it, else the schema's default."""
    return float(z.get(name, schema_default("zone", name)))


def _zone(check, z, where, zone_names, explicit, next_id, schedules):
    heat_input = z.get("heat_input")
    heat_input = () if heat_input is None else (heat_input,) if isinstance(heat_input, str) else tuple(heat_input)
    supply = z.get("supply")
    if supply is not None:
        supply = Supply(flow=float(supply["flow"]), temperature=_temperature(supply["temperature"]),
                        flow_factor=float(supply.get("flow_factor", schema_default("zone", "supply", "flow_factor"))))
    for j, raw in enumerate(z.get("airflow_from", ())):
        if raw["zone"] not in zone_names:
            check.fail(f"{where}.airflow_from[{j}].zone", f"names no zone ({raw['zone']!r})")
        if raw["zone"] == z["name"]:
            check.fail(f"{where}.airflow_from[{j}].zone", "air cannot flow from a zone into itself")
    daily, workday = z.get("daily_gain"), z.get("workday_gain")
    exchange = z.get("air_exchange", {})
    for other in exchange:
        if other not in zone_names:
            check.fail(f"{where}.air_exchange.{other}", f"names no zone ({other!r})")
        if other == z["name"]:
            check.fail(f"{where}.air_exchange.{other}", "a zone exchanges no air with itself")
    if explicit:
        air, radiant = z["air_node"], z["radiant_node"]
    else:
        air, radiant = next(next_id), next(next_id)
    return Zone(
        name=z["name"],
        volume=float(z["volume"]),
        air_node=air,
        radiant_node=radiant,
        air_change_rate=_zone_value(z, "air_change_rate"),
        internal_gain=_zone_value(z, "internal_gain"),
        heat_input=heat_input,
        heat_input_radiative_fraction=_zone_value(z, "heat_input_radiative_fraction"),
        supply=supply,
        airflow_from=tuple(Inflow(zone=raw["zone"], flow=float(raw["flow"])) for raw in z.get("airflow_from", ())),
        thermal_bridges=_floats(z.get("thermal_bridges", {})),
        convection_factor=_zone_value(z, "convection_factor"),
        occupied=z.get("occupied"),
        daily_gain=() if daily is None else tuple(
            (t, float(daily.get(t, schema_default("zone", "daily_gain", t)))) for t in DAY_TERMS),
        workday_gain=() if workday is None else tuple(
            (t, float(workday.get(t, schema_default("zone", "workday_gain", t)))) for t in WORKDAY_TERMS),
        proportional_gains=_floats(z.get("proportional_gains", {})),
        envelope_factor=_zone_value(z, "envelope_factor"),
        shading_transmittance=_zone_value(z, "shading_transmittance"),
        heat_input_factor=_zone_value(z, "heat_input_factor"),
        air_exchange=_floats(exchange),
        gains=_gains(check, z, where, schedules),
        ventilation=_ventilation(check, z, where, schedules),
        internal_mass=_lumped(z.get("internal_mass")),
        heat_input_lag=_lumped(z.get("heat_input_lag")),
        longwave=z.get("longwave", schema_default("zone", "longwave")),
        view_factors=tuple((a, b, float(F)) for a, row in z.get("view_factors", {}).items() for b, F in row.items()),
        longwave_followed=z.get("longwave_followed", schema_default("zone", "longwave_followed")),
        inside_convection_algorithm=z.get("inside_convection_algorithm",
                                          schema_default("zone", "inside_convection_algorithm")),
    )


def _floats(mapping):
    """((key, value as float), ...) of a JSON object of numbers, in its order."""
    return tuple((key, float(value)) for key, value in mapping.items())


def _temperature(value):
    """A temperature: C (a float), or the name of an input column or a schedule."""
    return value if isinstance(value, str) else float(value)


def _lumped(raw):
    """The `Lumped` node a zone effect declares, or None."""
    return None if raw is None else Lumped(capacity=float(raw["capacity"]), conductance=float(raw["conductance"]))


def _number_added_nodes(zones, last):
    """The zones with ids for the nodes their effects add: after the building's `last` node, zone
    by zone in file order, its internal mass before its heater (docs/model.md section 7)."""
    ids = iter(range(last + 1, 10 ** 9))
    numbered = []
    for z in zones:
        mass = next(ids) if z.internal_mass is not None else None
        heater = next(ids) if z.heat_input_lag is not None else None
        numbered.append(replace(z, mass_node=mass, heater_node=heater))
    return tuple(numbered)


def _surface(check, raw, where, zone_names):
    if raw["zone"] not in zone_names:
        check.fail(f"{where}.zone", f"names no zone ({raw['zone']!r})")
    if raw.get("solar_absorptance", 0.0) + raw.get("diffuse_transmittance", 0.0) > 1.0:
        check.fail(f"{where}.diffuse_transmittance", "with solar_absorptance exceeds 1: the face would give more sun than it gets")
    return Surface(zone=raw["zone"], h_conv=float(raw["h_conv"]), h_rad=float(raw["h_rad"]),
                   emissivity=float(raw.get("emissivity", schema_default("inside", "emissivity"))),
                   face_class=raw.get("face_class"), solar_absorptance=raw.get("solar_absorptance"),
                   diffuse_transmittance=float(raw.get("diffuse_transmittance", 0.0)))


def _outside(check, raw, where, zone_names):
    kind = raw["type"]
    if kind == "exterior":
        return Exterior(h_conv=float(raw["h_conv"]), h_rad=float(raw["h_rad"]),
                        solar_absorptance=float(raw["solar_absorptance"]), irradiance=raw.get("irradiance"),
                        sky_view_factor=float(raw["sky_view_factor"]) if "sky_view_factor" in raw else None,
                        convection=_outside_convection(raw.get("convection")),
                        longwave_emissivity=float(raw["longwave"]["emissivity"]) if "longwave" in raw else None)
    if kind == "zone":
        return _surface(check, raw, where, zone_names)
    if kind == "boundary":
        return Boundary(temperature=_temperature(raw["temperature"]), h=float(raw["h"]))
    if kind == "inside_face":
        return InsideFace()
    return Adiabatic()


def _outside_convection(raw):
    """The `OutsideConvection` an exterior face declares, or None (its h_conv constant)."""
    if raw is None:
        return None
    default = functools.partial(schema_default, "outside_exterior", "convection")
    return OutsideConvection(algorithm=raw["algorithm"], roughness=float(raw.get("roughness", default("roughness"))),
                             wind_factor=float(raw.get("wind_factor", default("wind_factor"))))


def _layers(check, c, where, materials):
    for j, (material, _) in enumerate(c["layers"]):
        if material not in materials:
            check.fail(f"{where}.layers[{j}]", f"unknown material {material!r}")
    return tuple((materials[material], float(thickness)) for material, thickness in c["layers"])


def _depths(check, c, where, layers, sensor_depths):
    """(explicit ids or None, depths) of a component's nodes."""
    total = sum(t for _, t in layers)
    raw_nodes = c["nodes"]
    if isinstance(raw_nodes, dict):
        return None, generated_depths([t for _, t in layers], float(raw_nodes["max_spacing"]),
                                      raw_nodes.get("layer_boundaries", schema_default("node_rule", "layer_boundaries")),
                                      sensor_depths.get(c["name"], ()))
    ids, depths = [node["id"] for node in raw_nodes], [float(node["depth"]) for node in raw_nodes]
    for j, depth in enumerate(depths):
        if depth > total + DEPTH_TOLERANCE:
            check.fail(f"{where}.nodes[{j}].depth", f"{depth} m is outside the component (0 to {total:g} m)")
    if not _increasing(depths):
        check.fail(f"{where}.nodes", "depths must increase strictly from the inside face")
    if abs(depths[0]) > DEPTH_TOLERANCE:
        check.fail(f"{where}.nodes[0].depth", "the first node must be at depth 0 (the inside surface)")
    if abs(depths[-1] - total) > DEPTH_TOLERANCE:
        check.fail(f"{where}.nodes[{len(depths) - 1}].depth",
                   f"the last node must be at the outside surface, {total:g} m")
    depths[0], depths[-1] = 0.0, total
    return tuple(ids), depths


def _component(check, c, where, materials, zone_names, sensor_depths):
    """The fields of a Component (node ids left out where the tool assigns them)."""
    layers = _layers(check, c, where, materials)
    ids, depths = _depths(check, c, where, layers, sensor_depths)
    tau = c.get("solar_transmittance")
    return dict(
        name=c["name"],
        area=float(c["area"]),
        tilt=float(c["tilt"]),
        azimuth=float(c["azimuth"]),
        layers=layers,
        node_ids=ids,
        depths=tuple(depths),
        inside=_surface(check, c["inside"], f"{where}.inside", zone_names),
        outside=_outside(check, c["outside"], f"{where}.outside", zone_names),
        solar_transmittance=None if tau is None else float(tau),
        transmitted_solar_to=c["transmitted_solar_to"] if tau is not None else None,
        shading=c.get("shading"),
        conductivity_factor=float(c.get("conductivity_factor", schema_default("component", "conductivity_factor"))),
        capacity_factor=float(c.get("capacity_factor", schema_default("component", "capacity_factor"))),
        angular=_angular(check, c, where),
        angular_absorptance=_angular_absorptance(check, c, where),
        solar_distribution=_distribution(check, c, where, "solar_distribution"),
        diffuse_distribution=_distribution(check, c, where, "diffuse_distribution"),
        traced_beam=tuple((face, _distribution(check, {face: split}, f"{where}.traced_beam", face))
                          for face, split in c.get("traced_beam", {}).items()),
        inner_solar_absorptance=float(c.get("inner_solar_absorptance",
                                            schema_default("component", "inner_solar_absorptance"))),
        vertices=_face_polygon(check, c, where),
        holes=tuple(_polygon(h) for h in c.get("holes", ())),
        window=_window(check, c, where, layers, depths),
    )


def gap_nodes(layers, depths, layer):
    """(i, i + 1): the positions among a component's node depths of the two faces of its layer
    `layer` (from 0 at the inside face), or None where a node lies within the layer or none on a
    face (the gap's conductance is then no single link between two panes)."""
    bounds = np.concatenate([[0.0], np.cumsum([t for _, t in layers])])
    depths = np.asarray(depths, dtype=float)
    at = [np.flatnonzero(np.abs(depths - bounds[k]) <= DEPTH_TOLERANCE) for k in (layer, layer + 1)]
    if any(len(a) != 1 for a in at) or at[1][0] != at[0][0] + 1:
        return None
    return int(at[0][0]), int(at[1][0])


def _window(check, c, where, layers, depths):
    """A component's `window` (docs/model.md section 4.1): each gap a gas layer between two
    panes, with a node on each of its faces and none within."""
    raw = c.get("window")
    if raw is None:
        return None
    gaps = []
    for j, g in enumerate(raw.get("gaps", ())):
        gw = f"{where}.window.gaps[{j}]"
        layer = int(g["layer"])
        if not 0 < layer < len(layers) - 1:
            check.fail(f"{gw}.layer", f"{layer} is no layer between two others (0 to {len(layers) - 1})")
        if gap_nodes(layers, depths, layer) is None:
            check.fail(f"{gw}.layer", f"layer {layer} needs a node on each of its faces and none within")
        gas = g.get("gas", "air")
        if isinstance(gas, dict):
            gas = tuple(tuple(float(x) for x in gas[p]) for p in ("conductivity", "viscosity", "specific_heat")) + (
                float(gas["molecular_weight"]),)
        elif isinstance(gas, list):
            for name, _ in gas:
                if name not in GASES:
                    check.fail(f"{gw}.gas", f"{name!r} is none of {', '.join(GASES)}")
            gas = [(name, float(x)) for name, x in gas]
        gaps.append(WindowGap(layer=layer, emissivities=tuple(float(e) for e in g["emissivities"]), gas=gas))
    return Window(height=float(raw["height"]), gaps=tuple(gaps))


# How far (deg) a face's vertices may turn from its declared tilt and azimuth: a converter's are
# rounded to 1e-6 deg, a hand-written file's to a degree at worst
ORIENTATION_TOLERANCE = 1.0


def _polygon(raw):
    return tuple(tuple(float(x) for x in p) for p in raw)


def _face_polygon(check, c, where):
    """A component's outside polygon, checked to enclose an area and to face its tilt and azimuth."""
    if "vertices" not in c:
        return None
    vertices = _polygon(c["vertices"])
    n = geometry.newell_normal(vertices)
    if np.linalg.norm(n) <= 1e-9:
        check.fail(f"{where}.vertices", "enclose no area")
    azimuth, tilt = geometry.azimuth_tilt(n / np.linalg.norm(n))
    if geometry.turned_from(n / np.linalg.norm(n), float(c["tilt"]), float(c["azimuth"])) > ORIENTATION_TOLERANCE:
        check.fail(f"{where}.vertices", f"face tilt {tilt:.1f} deg, azimuth {azimuth:.1f} deg (counterclockwise seen "
                                        f"from outside), not the component's {float(c['tilt']):g} and "
                                        f"{float(c['azimuth']):g}")
    return vertices


def _shading(check, data, components):
    """The file's shading surfaces, each naming exterior components that declare their vertices."""
    faces = {c.name: c for c in components}
    out = []
    for i, raw in enumerate(data.get("shading", ())):
        for name in raw["faces"]:
            c = faces.get(name)
            if c is None:
                check.fail(f"shading[{i}].faces", f"names no component ({name!r})")
            if c.vertices is None:
                check.fail(f"shading[{i}].faces", f"{name!r} declares no vertices for a shadow to fall on")
        out.append(ShadingSurface(name=raw["name"], vertices=_polygon(raw["vertices"]), faces=tuple(raw["faces"])))
    check.unique([s.name for s in out], "shading", "shading surface name")
    return tuple(out)


def _distribution(check, c, where, field):
    fractions = _floats(c.get(field, {}))
    if sum(f for _, f in fractions) > 1 + 1e-9:
        check.fail(f"{where}.{field}", f"the fractions add up to {sum(f for _, f in fractions):g}: at most "
                                                  "1 (the rest leaves through the glazings)")
    return fractions


def _check_traced_beam(check, where, c, by_name):
    """A glazing that traces its direct sun onto faces (docs/model.md 4.1) needs its direct sun
    apart (a diffuse_distribution) and the polygons of itself and of each face it names."""
    if not c.traced_beam:
        return
    where = f"{where}.traced_beam"
    if not c.diffuse_distribution:
        check.fail(where, "needs a diffuse_distribution: the direct sun is traced apart from the diffuse")
    if c.vertices is None:
        check.fail(where, "needs the glazing's vertices, the polygon its direct sun comes through")
    for face, split in c.traced_beam:
        if face not in by_name:
            check.fail(f"{where}.{face}", f"names no component ({face!r})")
        if by_name[face].vertices is None:
            check.fail(f"{where}.{face}", "declares no vertices for the direct sun to fall on")
        for name, _ in split:
            if name not in by_name:
                check.fail(f"{where}.{face}.{name}", f"names no component ({name!r})")


def _explicit_ids(check, raw_zones, components):
    """Whether the file numbers its nodes itself: every id given, or none."""
    given = [c["node_ids"] is not None for c in components] + ["air_node" in z for z in raw_zones]
    if any(given) and not all(given):
        check.fail("nodes", "give every node id (explicit node lists and each zone's air_node and "
                            "radiant_node) or none, for the tool to number them")
    return all(given)


def _sensor_depths(check, raw_sensors, raw_components):
    """{component name: depths of the sensors declared on it}, for node generation (a face
    always has a node)."""
    names = {c["name"] for c in raw_components}
    depths = {}
    for name, raw in raw_sensors.items():
        if "component" in raw:
            if raw["component"] not in names:
                check.fail(f"sensors.{name}.component", f"names no component ({raw['component']!r})")
            if "depth" in raw:
                depths.setdefault(raw["component"], []).append(float(raw["depth"]))
    return depths


def _sensor_node(check, name, raw, zones, components):
    where = f"sensors.{name}"
    if "zone" in raw:
        zone = next((z for z in zones if z.name == raw["zone"]), None)
        if zone is None:
            check.fail(f"{where}.zone", f"names no zone ({raw['zone']!r})")
        return zone.air_node
    c = next(c for c in components if c.name == raw["component"])
    if "face" in raw:
        return c.node_ids[0] if raw["face"] == "inside" else c.node_ids[-1]
    depth = raw["depth"]
    k = min(range(len(c.depths)), key=lambda k: abs(c.depths[k] - depth))
    if abs(c.depths[k] - depth) > SENSOR_TOLERANCE:
        check.fail(f"{where}.depth", f"{c.name} has no node at {depth} m (nodes at "
                                     f"{', '.join(f'{d:.3f}' for d in c.depths)} m)")
    return c.node_ids[k]


def _check_proportional_columns(check, zones, components):
    """A proportional gain scales a heat input or a face's irradiance the building already reads."""
    columns = [name for z in zones for name in z.heat_input]
    columns += [c.irradiance_input for c in components if isinstance(c.outside, Exterior)]
    for i, z in enumerate(zones):
        for column, _ in z.proportional_gains:
            if column not in columns:
                check.fail(f"zones[{i}].proportional_gains.{column}",
                           f"names no heat input or face irradiance of the building (one of: {', '.join(columns) or 'none'})")


def _boundary_factors(check, data, zones, components):
    """{column: factor} of `boundary_conductance_factors`: each a boundary column of the building."""
    raw = data.get("boundary_conductance_factors", {})
    columns = boundary_columns(zones, components)
    for column in raw:
        if column not in columns:
            check.fail(f"boundary_conductance_factors.{column}", f"names no boundary temperature column of the "
                                                                 f"building (one of: {', '.join(columns) or 'none'})")
    return dict(_floats(raw))


def _check_air_exchanges(check, zones):
    """An exchange between two zones is declared on one of them only: declared on both, whether
    one exchange or two is meant is not the tool's to guess."""
    for i, z in enumerate(zones):
        for other, _ in z.air_exchange:
            if z.name in dict(next(o for o in zones if o.name == other).air_exchange):
                check.fail(f"zones[{i}].air_exchange.{other}",
                           f"the exchange between {z.name} and {other} is declared on both zones: declare it once")


def _check_view_factors(check, zones, components):
    """A zone's declared view factors, and its followed long-wave, are for its ScriptF exchange;
    the view factors between faces it has, each named by one component, their rows summing to at
    most 1."""
    for i, z in enumerate(zones):
        if z.longwave_followed and z.longwave != "scriptf":
            check.fail(f"zones[{i}].longwave_followed", f"follows only longwave \"scriptf\", not {z.longwave!r}")
        if not z.view_factors:
            continue
        where = f"zones[{i}].view_factors"
        if z.longwave != "scriptf":
            check.fail(where, f"view factors are read only with longwave \"scriptf\", not {z.longwave!r}")
        faces = [c.name for c in components if c.inside.zone == z.name]
        faces += [c.name for c in components if isinstance(c.outside, Surface) and c.outside.zone == z.name]
        for a, b, _ in z.view_factors:
            for name in (a, b):
                if name not in faces:
                    check.fail(f"{where}.{a}", f"{name!r} is no face of zone {z.name!r}")
                if faces.count(name) > 1:
                    check.fail(f"{where}.{a}", f"{name!r} faces zone {z.name!r} on both sides: its faces "
                                               "cannot be told apart by name")
        for a in dict.fromkeys(a for a, _, _ in z.view_factors):
            total = sum(F for row, _, F in z.view_factors if row == a)
            if total > 1 + 1e-6:
                check.fail(f"{where}.{a}", f"the view factors add up to {total:g}: at most 1")


def _check_node_ids(check, zones, components):
    ids = [z.air_node for z in zones] + [z.radiant_node for z in zones]
    ids += [i for c in components for i in c.node_ids]
    check.unique(ids, "nodes", "node id")
    expected = set(range(1, len(ids) + 1))
    if set(ids) != expected:
        missing = sorted(expected - set(ids))
        extra = sorted(set(ids) - expected)
        detail = []
        if missing:
            detail.append(f"missing {missing[:5]}")
        if extra:
            detail.append(f"unexpected {extra[:5]}")
        check.fail("nodes", f"node ids must be 1..{len(ids)} with no gap ({'; '.join(detail)})")
