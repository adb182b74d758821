"""Read and validate a building file (`"format": "nodal-building/1"`, PHYSICS.md section 1).

Every check raises `InputError` naming the file and the field, so a user can fix the file
without reading code. The result is a tree of frozen dataclasses: the network is assembled
from it, never from the raw JSON.
"""
import json
import math
from dataclasses import dataclass, field

from .errors import InputError

FORMAT = "nodal-building/1"
OUTSIDE_TYPES = ("exterior", "adiabatic", "zone", "boundary")
# Depths are given in metres with a few decimals; a node "at" the outside face may be
# off by rounding only.
DEPTH_TOLERANCE = 1e-9


@dataclass(frozen=True)
class Material:
    conductivity: float  # W/m/K
    density: float  # kg/m3
    specific_heat: float  # J/kg/K


@dataclass(frozen=True)
class Zone:
    name: str
    volume: float  # m3
    air_node: int
    radiant_node: int
    air_change_rate: float = 0.0  # 1/h
    internal_gain: float = 0.0  # W
    heat_input: str | None = None  # name of an input column, W
    convection_factor: float = 1.0  # scale on the inside h_conv of the surfaces facing the zone


@dataclass(frozen=True)
class Component:
    name: str
    area: float  # m2
    tilt: float  # degrees from horizontal, 0 = facing up
    azimuth: float  # degrees clockwise from north
    layers: tuple  # ((Material, thickness m), ...) from the inside face outwards
    node_ids: tuple  # ids, ordered by depth
    depths: tuple  # m from the inside face
    inside: dict  # {"zone", "h_conv", "h_rad"}
    outside: dict  # {"type", ...} as in PHYSICS.md section 1
    solar_transmittance: float | None = None
    transmitted_solar_to: str | None = None
    conductivity_factor: float = 1.0  # scale on the conductances between its nodes

    @property
    def thickness(self):
        """Total thickness of the layers (m)."""
        return sum(t for _, t in self.layers)


@dataclass(frozen=True)
class Building:
    name: str
    site: dict  # latitude, longitude (deg), altitude (m), timezone, ground_albedo
    zones: tuple
    components: tuple
    source: str = field(default="<building>", compare=False)

    @property
    def n_nodes(self):
        return sum(len(c.node_ids) for c in self.components) + 2 * len(self.zones)

    @property
    def exterior_components(self):
        """Components whose outside face sees the outdoor air, sky and sun."""
        return tuple(c for c in self.components if c.outside["type"] == "exterior")

    @property
    def input_columns(self):
        """Names of measured input columns the building refers to (heat inputs, boundary
        temperatures), in order of appearance."""
        names = [z.heat_input for z in self.zones if z.heat_input]
        names += [c.outside["temperature"] for c in self.components
                  if c.outside["type"] == "boundary" and isinstance(c.outside["temperature"], str)]
        return tuple(dict.fromkeys(names))

    def zone(self, name):
        return next(z for z in self.zones if z.name == name)

    def component(self, name):
        return next(c for c in self.components if c.name == name)


def read_building_data(path):
    """The JSON content of a building file, validated; InputError if it is not a valid building.

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
    parse_building(data, source=str(path))
    _check_schema(data, str(path))
    return data


def _check_schema(data, source):
    # imported here: the FMU runs this module without jsonschema
    import jsonschema
    from importlib.resources import files
    schema = json.loads(files(__package__).joinpath("data/nodal-building.schema.json").read_text())
    error = jsonschema.exceptions.best_match(jsonschema.Draft202012Validator(schema).iter_errors(data))
    if error is not None:
        where = "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in error.absolute_path).lstrip(".")
        raise InputError(source, where or "(top level)", error.message)


def load_building(path):
    """Read and validate a building file; return a `Building`."""
    return parse_building(read_building_data(path), source=str(path))


def parse_building(data, source="<building>"):
    """Validate a building description already parsed from JSON; return a `Building`."""
    check = _Checker(source)
    if not isinstance(data, dict):
        check.fail("(top level)", "must be a JSON object")
    if data.get("format") != FORMAT:
        check.fail("format", f"must be {FORMAT!r}, found {data.get('format')!r}")
    site = _site(check, data.get("site"))
    materials = _materials(check, check.mapping(data, "materials", "(top level)"))
    zones = tuple(_zone(check, z, f"zones[{i}]")
                  for i, z in enumerate(check.sequence(data, "zones", "(top level)")))
    if not zones:
        check.fail("zones", "at least one zone is needed")
    zone_names = [z.name for z in zones]
    check.unique(zone_names, "zones", "zone name")
    raw_components = check.sequence(data, "components", "(top level)")
    components = tuple(_component(check, c, f"components[{i}]", materials, zone_names)
                       for i, c in enumerate(raw_components))
    check.unique([c.name for c in components], "components", "component name")
    names = {c.name for c in components}
    for i, c in enumerate(components):
        if c.transmitted_solar_to is not None and c.transmitted_solar_to not in names:
            check.fail(f"components[{i}].transmitted_solar_to",
                       f"names no component ({c.transmitted_solar_to!r})")
    _check_node_ids(check, zones, components)
    return Building(name=str(data.get("name", "")), site=site, zones=zones,
                    components=components, source=source)


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

    def sequence(self, obj, key, where):
        value = obj.get(key) if isinstance(obj, dict) else None
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


def _zone(check, z, where):
    if not isinstance(z, dict):
        check.fail(where, "must be an object")
    return Zone(
        name=check.text(z, "name", where),
        volume=check.number(z, "volume", where, low=0, low_open=True),
        air_node=check.integer(z, "air_node", where),
        radiant_node=check.integer(z, "radiant_node", where),
        air_change_rate=check.number(z, "air_change_rate", where, default=0.0, low=0),
        internal_gain=check.number(z, "internal_gain", where, default=0.0),
        heat_input=check.text(z, "heat_input", where, optional=True),
        convection_factor=check.number(z, "convection_factor", where, default=1.0, low=0, low_open=True),
    )


def _surface(check, raw, where, zone_names):
    if not isinstance(raw, dict):
        check.fail(where, "missing or not an object")
    zone = check.text(raw, "zone", where)
    if zone not in zone_names:
        check.fail(f"{where}.zone", f"names no zone ({zone!r})")
    return {"zone": zone,
            "h_conv": check.number(raw, "h_conv", where, low=0),
            "h_rad": check.number(raw, "h_rad", where, low=0)}


def _outside(check, raw, where, zone_names):
    if not isinstance(raw, dict):
        check.fail(where, "missing or not an object")
    kind = raw.get("type")
    if kind not in OUTSIDE_TYPES:
        check.fail(f"{where}.type", f"must be one of {', '.join(OUTSIDE_TYPES)}; found {kind!r}")
    if kind == "exterior":
        return {"type": kind,
                "h_conv": check.number(raw, "h_conv", where, low=0),
                "h_rad": check.number(raw, "h_rad", where, low=0),
                "solar_absorptance": check.number(raw, "solar_absorptance", where, low=0, high=1)}
    if kind == "zone":
        return {"type": kind, **_surface(check, raw, where, zone_names)}
    if kind == "boundary":
        temperature = raw.get("temperature")
        if isinstance(temperature, str):
            if not temperature:
                check.fail(f"{where}.temperature", "an empty column name")
        else:
            temperature = check.number(raw, "temperature", where, low=-100, high=100)
        return {"type": kind, "temperature": temperature,
                "h": check.number(raw, "h", where, low=0, low_open=True)}
    return {"type": kind}


def _component(check, c, where, materials, zone_names):
    if not isinstance(c, dict):
        check.fail(where, "must be an object")
    name = check.text(c, "name", where)
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
        check.fail(f"{where}.layers", "at least one layer is needed")
    total = sum(t for _, t in layers)

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

    tau = c.get("solar_transmittance")
    if tau is not None:
        tau = check.number(c, "solar_transmittance", where, low=0, high=1)
        check.text(c, "transmitted_solar_to", where)
    return Component(
        name=name,
        area=check.number(c, "area", where, low=0, low_open=True),
        tilt=check.number(c, "tilt", where, low=0, high=180),
        azimuth=check.number(c, "azimuth", where, low=0, high=360),
        layers=tuple(layers),
        node_ids=tuple(ids),
        depths=tuple(depths),
        inside=_surface(check, c.get("inside"), f"{where}.inside", zone_names),
        outside=_outside(check, c.get("outside"), f"{where}.outside", zone_names),
        solar_transmittance=tau,
        transmitted_solar_to=c.get("transmitted_solar_to") if tau is not None else None,
        conductivity_factor=check.number(c, "conductivity_factor", where, default=1.0, low=0, low_open=True),
    )


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
