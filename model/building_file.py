"""Read and validate a building file (`"format": "nodal-building/1"`, docs/model.md section 1) into
the building's records (`building.py`).

Every check raises `InputError` naming the file and the field, so a user can fix the file
without reading code. Nodes are given explicitly (`"nodes": [{"id", "depth"}]`) or generated from
the layers (`"nodes": {"max_spacing": m}`), in which case the tool numbers every node: components
in file order, each inside to outside, then each zone's air and radiant node.
"""
import copy
import json
import math
import re
from dataclasses import replace

from .building import (DAY_TERMS, NODE_COLUMN, Adiabatic, AngularTransmittance, Boundary, Building, Component,
                       Exterior, Gain, Inflow, Lumped, Material, Supply, Surface, Ventilation, Zone,
                       boundary_columns)
from .discretise import generated_depths
from .errors import InputError
from .schedule import WEEKDAYS, Schedule

FORMAT = "nodal-building/1"
OUTSIDE_TYPES = ("exterior", "adiabatic", "zone", "boundary")
# Depths are given in metres with a few decimals; a node "at" the outside face may be
# off by rounding only.
DEPTH_TOLERANCE = 1e-9
# A sensor's depth names the node nearest it within this distance (m): positions in a building
# description are rounded to the millimetre.
SENSOR_TOLERANCE = 1e-3


def load_building(path):
    """Read and validate a building file; return a `Building`.

    Beyond `parse_building`'s checks, the file must follow the format's JSON Schema
    (`data/nodal-building.schema.json`), which refuses unknown fields: a misspelt optional
    field would otherwise be ignored and its default used in silence.
    """
    try:
        with open(path, encoding="utf-8") as f:
            data = json.load(f)
    except FileNotFoundError:
        raise InputError(path, "file", "not found") from None
    except json.JSONDecodeError as e:
        raise InputError(path, f"line {e.lineno}", f"not valid JSON ({e.msg})") from None
    building = parse_building(data, source=str(path))
    check_schema(data, str(path))
    return building


def check_schema(data, source):
    """InputError naming the field where `data` does not follow the format's JSON Schema."""
    # imported here: the FMU runs this module without jsonschema
    import jsonschema
    from importlib.resources import files
    schema = json.loads(files(__package__).joinpath("data/nodal-building.schema.json").read_text())
    error = jsonschema.exceptions.best_match(jsonschema.Draft202012Validator(schema).iter_errors(data))
    if error is not None:
        where = "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in error.absolute_path).lstrip(".")
        raise InputError(source, where or "(top level)", error.message)


def parse_building(data, source="<building>"):
    """Validate a building description already parsed from JSON; return a `Building`."""
    check = _Checker(source)
    if not isinstance(data, dict):
        check.fail("(top level)", "must be a JSON object")
    if data.get("format") != FORMAT:
        check.fail("format", f"must be {FORMAT!r}, found {data.get('format')!r}")
    site = _site(check, data.get("site"))
    schedules = _schedules(check, data.get("schedules", {}))
    materials = _materials(check, check.mapping(data, "materials", "(top level)"))
    raw_zones = check.sequence(data, "zones", "(top level)")
    if not raw_zones:
        check.fail("zones", "at least one zone is needed")
    zone_names = [check.text(z, "name", f"zones[{i}]") for i, z in enumerate(raw_zones)]
    check.unique(zone_names, "zones", "zone name")
    raw_components = check.sequence(data, "components", "(top level)")
    raw_sensors = data.get("sensors", {})
    if not isinstance(raw_sensors, dict):
        check.fail("sensors", "must be an object of sensor name: position")
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
    names = {c.name for c in components}
    for i, c in enumerate(components):
        if c.transmitted_solar_to is not None and c.transmitted_solar_to not in names:
            check.fail(f"components[{i}].transmitted_solar_to",
                       f"names no component ({c.transmitted_solar_to!r})")
        for name, _ in c.solar_distribution:
            if name not in names:
                check.fail(f"components[{i}].solar_distribution.{name}", f"names no component ({name!r})")
    _check_proportional_columns(check, zones, components)
    _check_air_exchanges(check, zones)
    boundary_factors = _boundary_factors(check, data, zones, components)
    _check_node_ids(check, zones, components)
    zones = _number_added_nodes(zones, sum(len(c.node_ids) for c in components) + 2 * len(zones))
    flux_sensors = {name: (raw["component"], raw["face"]) for name, raw in raw_sensors.items()
                    if raw.get("quantity") == "heat_flux"}
    sensors = {name: _sensor_node(check, name, raw, zones, components) for name, raw in raw_sensors.items()
               if name not in flux_sensors}
    return Building(name=str(data.get("name", "")), site=site, zones=zones, components=components,
                    sensors=sensors, flux_sensors=flux_sensors, boundary_factors=boundary_factors,
                    schedules=schedules, source=source, data=copy.deepcopy(data), reader=parse_building)


class _Checker:
    """Small typed accessors that fail with the file and field path."""

    def __init__(self, source):
        self.source = source

    def fail(self, where, problem):
        raise InputError(self.source, where, problem)

    def mapping(self, obj, key, where):
        value = obj.get(key) if isinstance(obj, dict) else None
        if not isinstance(value, dict):
            self.fail(_join(where, key), "missing or not an object")
        return value

    def sequence(self, obj, key, where, *, optional=False):
        value = obj.get(key) if isinstance(obj, dict) else None
        if value is None and optional:
            return []
        if not isinstance(value, list):
            self.fail(_join(where, key), "missing or not a list")
        return value

    def number(self, obj, key, where, *, default=None, low=None, high=None, low_open=False):
        value = obj.get(key, default) if isinstance(obj, dict) else default
        path = _join(where, key)
        if value is None:
            self.fail(path, "missing")
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            self.fail(path, f"must be a finite number, found {value!r}")
        if low is not None and (value <= low if low_open else value < low):
            self.fail(path, f"must be {'>' if low_open else '>='} {low}, found {value}")
        if high is not None and value > high:
            self.fail(path, f"must be <= {high}, found {value}")
        return float(value)

    def integer(self, obj, key, where):
        value = obj.get(key) if isinstance(obj, dict) else None
        if isinstance(value, bool) or not isinstance(value, int):
            self.fail(_join(where, key), f"must be an integer node id, found {value!r}")
        return value

    def text(self, obj, key, where, *, optional=False):
        value = obj.get(key) if isinstance(obj, dict) else None
        if value is None and optional:
            return None
        if not isinstance(value, str) or not value:
            self.fail(_join(where, key), "missing or not a non-empty string")
        return value

    def temperature(self, obj, key, where):
        """A temperature: a number (C) or the name of an input column."""
        value = obj.get(key) if isinstance(obj, dict) else None
        if isinstance(value, str):
            if not value:
                self.fail(_join(where, key), "an empty column name")
            return value
        return self.number(obj, key, where, low=-100, high=100)

    def unique(self, values, where, what):
        seen = set()
        for v in values:
            if v in seen:
                self.fail(where, f"{what} {v!r} appears twice")
            seen.add(v)


def _join(where, key):
    return key if where == "(top level)" else f"{where}.{key}"


def _site(check, site):
    if not isinstance(site, dict):
        check.fail("site", "missing or not an object")
    return {
        "latitude": check.number(site, "latitude", "site", low=-90, high=90),
        "longitude": check.number(site, "longitude", "site", low=-180, high=180),
        "altitude": check.number(site, "altitude", "site", default=0.0),
        "timezone": site.get("timezone", "UTC"),
        "ground_albedo": check.number(site, "ground_albedo", "site", default=0.2, low=0, high=1),
        "air_density": check.number(site, "air_density", "site", default=1.2, low=0, low_open=True, high=2),
    }


def _materials(check, raw):
    materials = {}
    for name, m in raw.items():
        where = f"materials.{name}"
        if not isinstance(m, dict):
            check.fail(where, "must be an object")
        materials[name] = Material(
            conductivity=check.number(m, "conductivity", where, low=0, low_open=True),
            density=check.number(m, "density", where, low=0),
            specific_heat=check.number(m, "specific_heat", where, low=0),
        )
    return materials


def _schedules(check, raw):
    """{name: Schedule} of the file's `schedules` (docs/model.md section 1.2)."""
    if not isinstance(raw, dict):
        check.fail("schedules", "must be an object {name: schedule}")
    return {name: _schedule(check, name, s, f"schedules.{name}") for name, s in raw.items()}


def _schedule(check, name, raw, where):
    if not isinstance(raw, dict) or ("constant" in raw) == ("periods" in raw):
        check.fail(where, 'must be {"constant": value} or {"days": {profile: [[until h, value], ...]}, '
                          '"periods": [{"through": "MM-DD", "week": [7 profile names, Monday first]}]}')
    if "constant" in raw:
        return Schedule(name=name, constant=check.number(raw, "constant", where))
    days = check.mapping(raw, "days", where)
    profiles = []
    for profile, pairs in days.items():
        pw = f"{where}.days.{profile}"
        if not isinstance(pairs, list) or not pairs:
            check.fail(pw, "must be a non-empty list of [until hour, value]")
        untils = []
        for k, pair in enumerate(pairs):
            if not (isinstance(pair, list) and len(pair) == 2):
                check.fail(f"{pw}[{k}]", "must be [until hour, value]")
            untils.append(check.number({"until": pair[0]}, "until", f"{pw}[{k}]", low=0, low_open=True, high=24))
            check.number({"value": pair[1]}, "value", f"{pw}[{k}]")
        if any(b <= a for a, b in zip(untils, untils[1:])) or untils[-1] != 24:
            check.fail(pw, "the hours until which each value holds must increase and end at 24")
        profiles.append((profile, tuple((float(u), float(v)) for u, v in pairs)))
    periods, last = [], 0
    for k, period in enumerate(check.sequence(raw, "periods", where)):
        pw = f"{where}.periods[{k}]"
        through = period.get("through") if isinstance(period, dict) else None
        match = re.fullmatch(r"(\d\d)-(\d\d)", through) if isinstance(through, str) else None
        if not match or not (1 <= int(match[1]) <= 12 and 1 <= int(match[2]) <= 31):
            check.fail(f"{pw}.through", f"must be a date MM-DD, found {through!r}")
        month, day = int(match[1]), int(match[2])
        if month * 100 + day <= last:
            check.fail(f"{pw}.through", "the periods' dates must increase")
        last = month * 100 + day
        week = period.get("week")
        if not (isinstance(week, list) and len(week) == len(WEEKDAYS)):
            check.fail(f"{pw}.week", "must list 7 profile names, Monday first")
        for d, profile in zip(WEEKDAYS, week):
            if profile not in days:
                check.fail(f"{pw}.week", f"{d}: names no profile of days ({profile!r})")
        periods.append(((month, day), tuple(week)))
    if last != 1231:
        check.fail(f"{where}.periods", "the last period must run through 12-31")
    return Schedule(name=name, days=tuple(profiles), periods=tuple(periods))


def _schedule_of(check, item, where, schedules):
    """The name of the schedule `item` follows (None: constant), checked to be one of the file's."""
    schedule = check.text(item, "schedule", where, optional=True)
    if schedule is not None and schedule not in schedules:
        check.fail(f"{where}.schedule", f"names no schedule of the file ({schedule!r})")
    return schedule


def _gains(check, z, where, schedules):
    gains = []
    for k, g in enumerate(check.sequence(z, "gains", where, optional=True)):
        gw = f"{where}.gains[{k}]"
        schedule = _schedule_of(check, g, gw, schedules)
        gains.append(Gain(name=check.text(g, "name", gw), power=check.number(g, "power", gw),
                          radiant_fraction=check.number(g, "radiant_fraction", gw, default=0.0, low=0, high=1),
                          schedule=schedule))
    return tuple(gains)


def _ventilation(check, z, where, schedules):
    flows = []
    for k, v in enumerate(check.sequence(z, "ventilation", where, optional=True)):
        vw = f"{where}.ventilation[{k}]"
        schedule = _schedule_of(check, v, vw, schedules)
        if schedule is not None and not schedules[schedule].is_constant and any(
                value < 0 for _, profile in schedules[schedule].days for _, value in profile):
            check.fail(f"{vw}.schedule", f"{schedule!r} takes negative values: an air flow is >= 0")
        flows.append(Ventilation(name=check.text(v, "name", vw), flow=check.number(v, "flow", vw, low=0),
                                 schedule=schedule))
    return tuple(flows)


def _angular(check, c, where):
    raw = c.get("angular_transmittance")
    if raw is None:
        return None
    where = f"{where}.angular_transmittance"
    if c.get("solar_transmittance") is None:
        check.fail(where, "only a glazed component (with a solar_transmittance) has one")
    if not isinstance(raw, dict):
        check.fail(where, 'must be {"angles": [deg], "factors": [-], "diffuse": -}')
    angles, factors = check.sequence(raw, "angles", where), check.sequence(raw, "factors", where)
    if len(angles) != len(factors) or len(angles) < 2:
        check.fail(where, "angles and factors must be lists of one length, at least 2")
    angles = [check.number({"a": a}, "a", f"{where}.angles[{k}]", low=0, high=90) for k, a in enumerate(angles)]
    factors = [check.number({"f": f}, "f", f"{where}.factors[{k}]", low=0) for k, f in enumerate(factors)]
    if angles[0] != 0 or any(b <= a for a, b in zip(angles, angles[1:])):
        check.fail(f"{where}.angles", "must start at 0 and increase")
    return AngularTransmittance(angles=tuple(angles), factors=tuple(factors),
                                diffuse=check.number(raw, "diffuse", where, low=0))


def _zone(check, z, where, zone_names, explicit, next_id, schedules):
    if not isinstance(z, dict):
        check.fail(where, "must be an object")
    heat_input = z.get("heat_input")
    if heat_input is None:
        heat_input = ()
    elif isinstance(heat_input, str):
        heat_input = (check.text(z, "heat_input", where),)
    elif isinstance(heat_input, list) and all(isinstance(h, str) and h for h in heat_input):
        heat_input = tuple(heat_input)
    else:
        check.fail(f"{where}.heat_input", "must be a column name or a list of column names")
    supply = None
    if z.get("supply") is not None:
        raw = check.mapping(z, "supply", where)
        supply = Supply(flow=check.number(raw, "flow", f"{where}.supply", low=0),
                        temperature=check.temperature(raw, "temperature", f"{where}.supply"),
                        flow_factor=check.number(raw, "flow_factor", f"{where}.supply", default=1.0, low=0))
    inflows = []
    for j, raw in enumerate(check.sequence(z, "airflow_from", where, optional=True)):
        fw = f"{where}.airflow_from[{j}]"
        source_zone = check.text(raw, "zone", fw)
        if source_zone not in zone_names:
            check.fail(f"{fw}.zone", f"names no zone ({source_zone!r})")
        if source_zone == z.get("name"):
            check.fail(f"{fw}.zone", "air cannot flow from a zone into itself")
        inflows.append(Inflow(zone=source_zone, flow=check.number(raw, "flow", fw, low=0)))
    bridges = z.get("thermal_bridges", {})
    if not isinstance(bridges, dict):
        check.fail(f"{where}.thermal_bridges", 'must be an object {"outdoor" or column: UA in W/K}')
    bridges = tuple((to, check.number(bridges, to, f"{where}.thermal_bridges", low=0)) for to in bridges)
    daily = z.get("daily_gain")
    if daily is not None:
        if not isinstance(daily, dict) or set(daily) - set(DAY_TERMS):
            check.fail(f"{where}.daily_gain", f"must be an object of W with keys among {', '.join(DAY_TERMS)}")
        daily = tuple((t, check.number(daily, t, f"{where}.daily_gain", default=0.0)) for t in DAY_TERMS)
    proportional = z.get("proportional_gains", {})
    if not isinstance(proportional, dict):
        check.fail(f"{where}.proportional_gains", "must be an object {input column: k in W per unit of the column}")
    proportional = tuple((column, check.number(proportional, column, f"{where}.proportional_gains"))
                         for column in proportional)
    lumped = {key: _lumped(check, z, key, where) for key in ("internal_mass", "heat_input_lag")}
    if lumped["heat_input_lag"] is not None and not heat_input:
        check.fail(f"{where}.heat_input_lag", "the zone has no heat_input whose heater it would delay")
    if "heat_input_factor" in z and not heat_input:
        check.fail(f"{where}.heat_input_factor", "the zone has no heat_input whose reading it would scale")
    exchange = z.get("air_exchange", {})
    if not isinstance(exchange, dict):
        check.fail(f"{where}.air_exchange", 'must be an object {"other zone": m3/h each way}')
    for other in exchange:
        if other not in zone_names:
            check.fail(f"{where}.air_exchange.{other}", f"names no zone ({other!r})")
        if other == z.get("name"):
            check.fail(f"{where}.air_exchange.{other}", "a zone exchanges no air with itself")
    exchange = tuple((other, check.number(exchange, other, f"{where}.air_exchange", low=0)) for other in exchange)
    occupied = z.get("occupied")
    if occupied is not None and not isinstance(occupied, bool):
        check.fail(f"{where}.occupied", f"must be true or false, found {occupied!r}")
    if explicit:
        air, radiant = check.integer(z, "air_node", where), check.integer(z, "radiant_node", where)
    else:
        air, radiant = next(next_id), next(next_id)
    return Zone(
        name=z["name"],
        volume=check.number(z, "volume", where, low=0, low_open=True),
        air_node=air,
        radiant_node=radiant,
        air_change_rate=check.number(z, "air_change_rate", where, default=0.0, low=0),
        internal_gain=check.number(z, "internal_gain", where, default=0.0),
        heat_input=heat_input,
        heat_input_radiative_fraction=check.number(z, "heat_input_radiative_fraction", where, default=0.0,
                                                   low=0, high=1),
        supply=supply,
        airflow_from=tuple(inflows),
        thermal_bridges=bridges,
        convection_factor=check.number(z, "convection_factor", where, default=1.0, low=0, low_open=True),
        occupied=occupied,
        daily_gain=daily or (),
        proportional_gains=proportional,
        envelope_factor=check.number(z, "envelope_factor", where, default=1.0, low=0, low_open=True),
        shading_transmittance=check.number(z, "shading_transmittance", where, default=0.0, low=0, high=1),
        heat_input_factor=check.number(z, "heat_input_factor", where, default=1.0, low=0),
        air_exchange=exchange,
        gains=_gains(check, z, where, schedules),
        ventilation=_ventilation(check, z, where, schedules),
        **lumped,
    )


def _lumped(check, z, key, where):
    """The `Lumped` node a zone effect declares under `key`, or None."""
    raw = z.get(key)
    if raw is None:
        return None
    if not isinstance(raw, dict):
        check.fail(f"{where}.{key}", 'must be {"capacity": J/K, "conductance": W/K}')
    return Lumped(capacity=check.number(raw, "capacity", f"{where}.{key}", low=0),
                  conductance=check.number(raw, "conductance", f"{where}.{key}", low=0, low_open=True))


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
    if not isinstance(raw, dict):
        check.fail(where, "missing or not an object")
    zone = check.text(raw, "zone", where)
    if zone not in zone_names:
        check.fail(f"{where}.zone", f"names no zone ({zone!r})")
    return Surface(zone=zone, h_conv=check.number(raw, "h_conv", where, low=0),
                   h_rad=check.number(raw, "h_rad", where, low=0))


def _outside(check, raw, where, zone_names):
    if not isinstance(raw, dict):
        check.fail(where, "missing or not an object")
    kind = raw.get("type")
    if kind not in OUTSIDE_TYPES:
        check.fail(f"{where}.type", f"must be one of {', '.join(OUTSIDE_TYPES)}; found {kind!r}")
    if kind == "exterior":
        return Exterior(h_conv=check.number(raw, "h_conv", where, low=0),
                        h_rad=check.number(raw, "h_rad", where, low=0),
                        solar_absorptance=check.number(raw, "solar_absorptance", where, low=0, high=1),
                        irradiance=check.text(raw, "irradiance", where, optional=True),
                        sky_view_factor=(check.number(raw, "sky_view_factor", where, low=0, high=1)
                                         if "sky_view_factor" in raw else None))
    if kind == "zone":
        return _surface(check, raw, where, zone_names)
    if kind == "boundary":
        return Boundary(temperature=check.temperature(raw, "temperature", where),
                        h=check.number(raw, "h", where, low=0, low_open=True))
    return Adiabatic()


def _layers(check, c, where, materials):
    layers = []
    for j, layer in enumerate(check.sequence(c, "layers", where)):
        lw = f"{where}.layers[{j}]"
        if not (isinstance(layer, list) and len(layer) == 2):
            check.fail(lw, "must be [material name, thickness in m]")
        material, thickness = layer
        if material not in materials:
            check.fail(lw, f"unknown material {material!r}")
        if isinstance(thickness, bool) or not isinstance(thickness, (int, float)) or not thickness > 0:
            check.fail(lw, f"thickness must be a positive number of metres, found {thickness!r}")
        layers.append((materials[material], float(thickness)))
    if not layers:
        check.fail(f"{where}.layers", "at least one layer is needed (listed from the inside face outwards)")
    return tuple(layers)


def _depths(check, c, where, layers, sensor_depths):
    """(explicit ids or None, depths) of a component's nodes."""
    total = sum(t for _, t in layers)
    raw_nodes = c.get("nodes")
    if isinstance(raw_nodes, dict):
        spacing = check.number(raw_nodes, "max_spacing", f"{where}.nodes", low=0, low_open=True)
        boundaries = raw_nodes.get("layer_boundaries", True)
        if not isinstance(boundaries, bool):
            check.fail(f"{where}.nodes.layer_boundaries", f"must be true or false, found {boundaries!r}")
        return None, generated_depths([t for _, t in layers], spacing, boundaries, sensor_depths.get(c.get("name"), ()))
    raw_nodes = check.sequence(c, "nodes", where)
    if len(raw_nodes) < 2:
        check.fail(f"{where}.nodes", "a component needs at least two nodes (inside and outside surface)")
    ids, depths = [], []
    for j, node in enumerate(raw_nodes):
        nw = f"{where}.nodes[{j}]"
        ids.append(check.integer(node, "id", nw))
        depth = check.number(node, "depth", nw)
        if depth < -DEPTH_TOLERANCE or depth > total + DEPTH_TOLERANCE:
            check.fail(f"{nw}.depth", f"{depth} m is outside the component (0 to {total:g} m)")
        depths.append(depth)
    if any(b <= a for a, b in zip(depths, depths[1:])):
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
    if not isinstance(c, dict):
        check.fail(where, "must be an object")
    name = check.text(c, "name", where)
    layers = _layers(check, c, where, materials)
    ids, depths = _depths(check, c, where, layers, sensor_depths)
    tau = c.get("solar_transmittance")
    if tau is not None:
        tau = check.number(c, "solar_transmittance", where, low=0, high=1)
        check.text(c, "transmitted_solar_to", where)
    shading = check.text(c, "shading", where, optional=True)
    if shading is not None and tau is None:
        check.fail(f"{where}.shading", "only a glazed component (with a solar_transmittance) has a shading")
    return dict(
        name=name,
        area=check.number(c, "area", where, low=0, low_open=True),
        tilt=check.number(c, "tilt", where, low=0, high=180),
        azimuth=check.number(c, "azimuth", where, low=0, high=360),
        layers=layers,
        node_ids=ids,
        depths=tuple(depths),
        inside=_surface(check, c.get("inside"), f"{where}.inside", zone_names),
        outside=_outside(check, c.get("outside"), f"{where}.outside", zone_names),
        solar_transmittance=tau,
        transmitted_solar_to=c.get("transmitted_solar_to") if tau is not None else None,
        shading=shading,
        conductivity_factor=check.number(c, "conductivity_factor", where, default=1.0, low=0, low_open=True),
        capacity_factor=check.number(c, "capacity_factor", where, default=1.0, low=0),
        angular=_angular(check, c, where),
        solar_distribution=_distribution(check, c, where, tau),
        inner_solar_absorptance=_inner_absorptance(check, c, where),
    )


def _inner_absorptance(check, c, where):
    if "inner_solar_absorptance" not in c:
        return 0.0
    if not (isinstance(c.get("outside"), dict) and c["outside"].get("type") == "exterior"):
        check.fail(f"{where}.inner_solar_absorptance", "only a component with an exterior outside face has one")
    return check.number(c, "inner_solar_absorptance", where, low=0, high=1)


def _distribution(check, c, where, tau):
    raw = c.get("solar_distribution")
    if raw is None:
        return ()
    where = f"{where}.solar_distribution"
    if tau is None:
        check.fail(where, "only a glazed component (with a solar_transmittance) has one")
    if not isinstance(raw, dict) or not raw:
        check.fail(where, 'must be {"component": fraction, ...}')
    fractions = tuple((name, check.number(raw, name, where, low=0, high=1)) for name in raw)
    if sum(f for _, f in fractions) > 1 + 1e-9:
        check.fail(where, f"the fractions add up to {sum(f for _, f in fractions):g}: at most 1 (the rest leaves "
                          "through the glazings)")
    return fractions


def _explicit_ids(check, raw_zones, components):
    """Whether the file numbers its nodes itself: every id given, or none."""
    given = [c["node_ids"] is not None for c in components]
    given += [isinstance(z, dict) and ("air_node" in z or "radiant_node" in z) for z in raw_zones]
    if any(given) and not all(given):
        check.fail("nodes", "give every node id (explicit node lists and each zone's air_node and "
                            "radiant_node) or none, for the tool to number them")
    return all(given)


FACES = ("inside", "outside")
QUANTITIES = ("temperature", "heat_flux")


def _sensor_depths(check, raw_sensors, raw_components):
    """{component name: depths of the sensors declared on it}, for node generation (a face
    always has a node)."""
    names = {c.get("name") for c in raw_components if isinstance(c, dict)}
    depths = {}
    for name, raw in raw_sensors.items():
        where = f"sensors.{name}"
        if NODE_COLUMN.match(name):
            check.fail(where, "a sensor name must not look like a node column T<id>")
        if not isinstance(raw, dict) or ("zone" in raw) == ("component" in raw):
            check.fail(where, 'must be {"zone": name}, {"component": name, "depth": m from the inside face} or '
                              '{"component": name, "face": "inside" or "outside"}')
        if "component" in raw:
            component = check.text(raw, "component", where)
            if component not in names:
                check.fail(f"{where}.component", f"names no component ({component!r})")
            if ("depth" in raw) == ("face" in raw):
                check.fail(where, "a component's sensor gives its depth (m from the inside face) or its face, "
                                  "one of them")
            if "face" in raw and raw["face"] not in FACES:
                check.fail(f"{where}.face", f"must be inside or outside, found {raw['face']!r}")
            quantity = raw.get("quantity", "temperature")
            if quantity not in QUANTITIES:
                check.fail(f"{where}.quantity", f"must be temperature or heat_flux, found {quantity!r}")
            if quantity == "heat_flux" and "face" not in raw:
                check.fail(f"{where}.quantity", "a heat flux is measured at a face: give its face, not a depth")
            if "depth" in raw:
                depths.setdefault(component, []).append(check.number(raw, "depth", where, low=0))
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
    where = "boundary_conductance_factors"
    if not isinstance(raw, dict):
        check.fail(where, "must be an object {boundary temperature column: factor}")
    columns = boundary_columns(zones, components)
    for column in raw:
        if column not in columns:
            check.fail(f"{where}.{column}", f"names no boundary temperature column of the building "
                                            f"(one of: {', '.join(columns) or 'none'})")
    return {column: check.number(raw, column, where, low=0) for column in raw}


def _check_air_exchanges(check, zones):
    """An exchange between two zones is declared on one of them only: declared on both, whether
    one exchange or two is meant is not the tool's to guess."""
    for i, z in enumerate(zones):
        for other, _ in z.air_exchange:
            if z.name in dict(next(o for o in zones if o.name == other).air_exchange):
                check.fail(f"zones[{i}].air_exchange.{other}",
                           f"the exchange between {z.name} and {other} is declared on both zones: declare it once")


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
