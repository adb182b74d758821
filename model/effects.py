"""The effects a diagnosis may add to a model (PHYSICS.md section 7), as changes to the building file.

Each effect is a change of declared fields, so a model with the effect is an ordinary building
file that every command loads, and its FMU exposes the effect's parameters as `<effect>.<name>`:

| effect              | target    | declared as                                                   |
|---------------------|-----------|---------------------------------------------------------------|
| ground_coupling     | component | its adiabatic outside face becomes a `boundary` at T_ground    |
|                     |           | through U (W/m2/K): A U (T_ground - T_e)                       |
| infiltration        | zone      | `air_change_rate` n (1/h)                                      |
| internal_gain       | zone      | `internal_gain` Q (W)                                          |
| solar_absorptance   | component | `outside.solar_absorptance` alpha                              |
| conductivity        | component | `conductivity_factor`: a scale on its conductances             |
| inside_convection   | zone      | `convection_factor`: a scale on the inside h_conv facing it    |
| solar_transmittance | component | `solar_transmittance` tau of a glazing                         |

Pure functions on the file's JSON content (dicts): the FMU runs this module too.
"""
import copy
from dataclasses import dataclass


@dataclass(frozen=True)
class Parameter:
    name: str
    unit: str
    low: float  # bounds of a calibration
    high: float


EFFECTS = {
    "ground_coupling": (Parameter("U", "W/m2/K", 0.0, 20.0), Parameter("T_ground", "C", -10.0, 40.0)),
    "infiltration": (Parameter("n", "1/h", 0.0, 20.0),),
    "internal_gain": (Parameter("Q", "W", -5000.0, 5000.0),),
    "solar_absorptance": (Parameter("alpha", "-", 0.0, 1.0),),
    "conductivity": (Parameter("factor", "-", 0.05, 20.0),),
    "inside_convection": (Parameter("factor", "-", 0.01, 20.0),),
    "solar_transmittance": (Parameter("tau", "-", 0.0, 1.0),),
}
ZONE_EFFECTS = ("infiltration", "internal_gain", "inside_convection")
# Where the calibration of an effect the file does not declare starts (see calibration_start).
ABSENT_START = {("ground_coupling", "U"): 1.0,  # W/m2/K
                ("infiltration", "n"): 0.5}  # 1/h


def _component(data, name):
    return next(c for c in data["components"] if c["name"] == name)


def _zone(data, name):
    return next(z for z in data["zones"] if z["name"] == name)


def applicable(data, effect, target):
    """Whether `effect` can be added to `target` (a component or zone name) of this building."""
    if effect in ZONE_EFFECTS:
        return any(z["name"] == target for z in data["zones"])
    c = next((c for c in data["components"] if c["name"] == target), None)
    if c is None:
        return False
    kind = c["outside"]["type"]
    if effect == "ground_coupling":
        return kind == "adiabatic"
    if effect == "solar_absorptance":
        return kind == "exterior"
    if effect == "solar_transmittance":
        return c.get("solar_transmittance") is not None
    return effect == "conductivity"


def current_values(data, effect, target):
    """The parameters' values the file declares now (their neutral values if not declared)."""
    if effect == "ground_coupling":
        out = _component(data, target)["outside"]
        if out["type"] == "boundary" and not isinstance(out["temperature"], str):
            return {"U": out["h"], "T_ground": out["temperature"]}
        return {"U": 0.0, "T_ground": 20.0}
    if effect in ZONE_EFFECTS:
        z = _zone(data, target)
        key = {"infiltration": "air_change_rate", "internal_gain": "internal_gain",
               "inside_convection": "convection_factor"}[effect]
        name = EFFECTS[effect][0].name
        return {name: float(z.get(key, 1.0 if effect == "inside_convection" else 0.0))}
    c = _component(data, target)
    if effect == "solar_absorptance":
        return {"alpha": c["outside"]["solar_absorptance"]}
    if effect == "solar_transmittance":
        return {"tau": c["solar_transmittance"]}
    return {"factor": float(c.get("conductivity_factor", 1.0))}


def calibration_start(data, effect, target):
    """Where a calibration starts: the declared values, except that an absent coupling (U = 0,
    n = 0) starts at `ABSENT_START`: on its bound, a bounded trust-region step is scaled to
    nothing and the fit stops where it began, and at U = 0 the ground temperature has no
    influence to fit at all."""
    values = current_values(data, effect, target)
    for name, value in values.items():
        if value == 0.0 and (effect, name) in ABSENT_START:
            values[name] = ABSENT_START[(effect, name)]
    return values


def apply(data, effect, target, values):
    """A copy of the building data with the effect declared at `values` ({name: value})."""
    data = copy.deepcopy(data)
    values = {**current_values(data, effect, target), **values}
    if effect == "ground_coupling":
        if values["U"] > 0:  # U = 0 is no coupling: the face stays as declared
            _component(data, target)["outside"] = {"type": "boundary", "temperature": float(values["T_ground"]),
                                                   "h": float(values["U"])}
    elif effect == "infiltration":
        _zone(data, target)["air_change_rate"] = float(values["n"])
    elif effect == "internal_gain":
        _zone(data, target)["internal_gain"] = float(values["Q"])
    elif effect == "inside_convection":
        _zone(data, target)["convection_factor"] = float(values["factor"])
    elif effect == "solar_absorptance":
        _component(data, target)["outside"]["solar_absorptance"] = float(values["alpha"])
    elif effect == "solar_transmittance":
        _component(data, target)["solar_transmittance"] = float(values["tau"])
    elif effect == "conductivity":
        _component(data, target)["conductivity_factor"] = float(values["factor"])
    else:
        raise KeyError(f"unknown effect {effect!r}")
    return data


def candidates(data, located_nodes):
    """(effect, target) pairs a diagnosis should try for the nodes the search located.

    The located nodes' components bring their own effects; the air node's own equation
    (infiltration, internal gain) is always a candidate, since no forcing can reveal it; when
    nothing was located, a change of the inside convection (no single node) is one as well.
    """
    owner = {n["id"]: c["name"] for c in data["components"] for n in c["nodes"]}
    components = list(dict.fromkeys(owner[i] for i in located_nodes if i in owner))
    pairs = []
    for name in components:
        for effect in ("ground_coupling", "solar_absorptance", "conductivity"):
            if applicable(data, effect, name):
                pairs.append((effect, name))
        pairs += [("solar_transmittance", c["name"]) for c in data["components"]
                  if c.get("transmitted_solar_to") == name and c.get("solar_transmittance") is not None]
    zones = [z["name"] for z in data["zones"]]
    pairs += [(effect, zone) for zone in zones for effect in ("infiltration", "internal_gain")]
    if not located_nodes:
        pairs += [("inside_convection", zone) for zone in zones]
    return list(dict.fromkeys(pairs))
