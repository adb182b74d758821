"""An EnergyPlus model (IDF) into a nodal-building file (`nodeforce convert`, docs/guide.md).

The IDF is read by idfkit (its epJSON schemas of EnergyPlus 8.9 to 26.x); a file of EnergyPlus
8.4 to 8.8 is read against the 8.9 schema, which the transitions 8.4 -> 8.9 leave unchanged for
every object this module reads but OtherEquipment (`to_schema_min`). What the building file holds is mapped (docs/guide.md lists each
object and field); what it cannot hold (HVAC, thermostats, EMS, shading devices, airflow
networks, a term of an air flow) is listed, one line per object, in the file's `not_modelled`;
an object the conversion needs and cannot read is an `InputError` naming the file, the object,
the field and the problem. The physics of the mapping (geometry, glazing) is `model.geometry` and
`model.glazing`; the coefficients EnergyPlus computes each step and the nodal model holds
constant are `FILMS`.
"""
import difflib
import functools
import re
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..model import beam_trace, convection, geometry, glazing, interior_sun, longwave
from ..model.building_file import ORIENTATION_TOLERANCE
from ..model.errors import InputError
from .energyplus_shading import fin, may_shade, on_surface, overhang, rectangle, window_frame
from .idf_text import closed_text
from ..model.gains import PEOPLE_T, people_sensible_heat, people_sensible_slope
from ..model.network import air_density_at, sky_fraction_energyplus
from ..model.shading import sky_diffuse_ratio

# 8.4 -> 8.5 changed no object read here (EnergyPlus's transition program for 8.5 renames an EMS
# actuator's value and report variables only)
MIN_VERSION, SCHEMA_MIN = (8, 4), (8, 9, 0)
# EnergyPlus's surface types as the classes of the approximate view factors (model.longwave):
# a ceiling is no roof there
FACE_CLASS = {"floor": "floor", "roof": "roof", "internalmass": "internal_mass"}


@dataclass(frozen=True)
class Films:
    """Surface coefficients the nodal model holds constant (W/m2/K), where EnergyPlus computes
    them each step: inside, the IDF's inside algorithm (TARP, EnergyPlus's default, or Simple:
    `model.convection.tarp_inside`, `simple_inside`) at a face-to-air difference of `delta_T`,
    every face warmer than the air (a floor the sun warms, a ceiling under the warm air); outside EnergyPlus's DOE-2 model (`model.convection.doe2`) at
    each face's height, roughness and the site's terrain for a weather station's wind of `wind`
    m/s (ISO 6946's reference, 4 m/s), natural convection alone where EnergyPlus says NoWind, at
    a face-to-air difference of `delta_T`; and the linearised long-wave exchange 4 sigma eps T_m^3
    of a face of emissivity eps at T_m."""
    wind: float = 4.0  # m/s at the weather station
    delta_T: float = 5.0  # K
    T_inside: float = 293.15  # K
    T_outside: float = 283.15  # K
    ground: float = 1000.0  # a face held at the ground's temperature, as EnergyPlus holds it

    def inside_convection(self, tilt, algorithm="tarp"):
        """h_c of an inside face of a component whose outside faces `tilt` (deg)."""
        if algorithm == "simple":
            return convection.simple_inside(tilt)
        return round(float(convection.tarp_inside(tilt, self.delta_T)), 4)

    def radiative(self, emissivity, T):
        return 4 * glazing.SIGMA * emissivity * T ** 3

    def outside_convection(self, tilt, height, roughness, wind_exposed, terrain):
        """h_c of an exterior face: DOE-2 at the local wind, or natural convection without wind."""
        if not wind_exposed:
            return convection.natural_convection(tilt, self.delta_T)
        return convection.doe2(tilt, convection.wind_at_height(self.wind, height, terrain), roughness, self.delta_T)


FILMS = Films()


def _named_split(faces, shares):
    """{component name: share} of a zone's `faces` (component, ...) and their `shares` (-), the
    shares of one component's faces summed (a partition's two sides in the zone) and rounded to 6
    places, the faces of no share left out."""
    split = {}
    for f, share in zip(faces, shares):
        if share > 0:
            split[f[0]["name"]] = split.get(f[0]["name"], 0.0) + float(share)
    return {name: round(share, 6) for name, share in split.items()}


def _sides(absorbed):
    """(outer, inner): the absorptances of a stack's panes (outside first) summed toward the face
    each is nearer, the outer half of the panes to the outside face, the inner half to the inside
    face, the middle pane of an odd number split."""
    n = len(absorbed)
    middle = absorbed[n // 2] / 2 if n % 2 else 0.0
    return float(sum(absorbed[:n // 2]) + middle), float(sum(absorbed[(n + 1) // 2:]) + middle)


# An air flow's wind is the station's at the height of the zone's surfaces' centroids
FLOW_WIND_HEIGHT = 1.5  # m, a zone's height where its surfaces give none
# A surface's vertices off its plane: listed beyond 2 cm, refused beyond a tenth of its size
PLANAR_LISTED, PLANAR_REFUSED = 0.02, 0.1  # m, fraction of sqrt(area)
# A window's panes and gaps hold no heat: EnergyPlus balances them at each step without capacity
# (WindowManager.cc, SolveForWindowTemperatures), and its glazing objects declare none
WINDOW_LAYER_CAPACITY = {"density": 0.0, "specific_heat": 0.0}
# A massless layer (Material:NoMass, Material:AirGap) is written as a layer this thick with its
# resistance and no capacity: only thickness / conductivity matters
MASSLESS_THICKNESS = 0.001  # m
# Material:InfraredTransparent as EnergyPlus holds it (Material.cc): a massless layer whose faces
# absorb all the sun and (nearly) all long-wave radiation
IR_TRANSPARENT_RESISTANCE = 0.01  # m2K/W
IR_TRANSPARENT_FACE = {"emissivity": 0.9999, "solar": 1.0}
THERMOCHROMIC_T = 20.0  # C, the pane temperature at which a thermochromic group's optics are taken
PANES = ("WINDOWMATERIAL:GLAZING", "WINDOWMATERIAL:GLAZING:REFRACTIONEXTINCTIONMETHOD")
MAX_SPACING = 0.025  # m, the largest cell of a generated component
# EnergyPlus's ground temperature where the IDF gives none (its Site:GroundTemperature:BuildingSurface default)
DEFAULT_GROUND = 18.0  # C
# ... and its Site:GroundTemperature:Deep's, for a month the object leaves blank
DEFAULT_DEEP_GROUND = 16.0  # C
MONTHS = ("january", "february", "march", "april", "may", "june", "july", "august", "september", "october",
          "november", "december")

SURFACES = ("BuildingSurface:Detailed", "Wall:Detailed", "RoofCeiling:Detailed", "Floor:Detailed")
SIMPLE_SURFACES = {  # type: (surface type, outside boundary)
    "Wall:Exterior": ("Wall", "Outdoors"), "Wall:Adiabatic": ("Wall", "Adiabatic"),
    "Wall:Underground": ("Wall", "Ground"), "Wall:Interzone": ("Wall", "Interzone"),
    "Roof": ("Roof", "Outdoors"), "Ceiling:Adiabatic": ("Ceiling", "Adiabatic"),
    "Ceiling:Interzone": ("Ceiling", "Interzone"), "Floor:GroundContact": ("Floor", "Ground"),
    "Floor:Adiabatic": ("Floor", "Adiabatic"), "Floor:Interzone": ("Floor", "Interzone"),
}
SUBSURFACES = ("FenestrationSurface:Detailed", "Window", "Door", "GlazedDoor", "Window:Interzone",
               "Door:Interzone", "GlazedDoor:Interzone")
GAINS = ("People", "Lights", "ElectricEquipment", "GasEquipment", "HotWaterEquipment", "SteamEquipment",
         "OtherEquipment")
# A gain's design level by its calculation method: the field each method reads (as 8.9's IDD names it)
GAIN_FIELDS = {kind: {"equipmentlevel": "design_level", "watts/area": "power_per_zone_floor_area",
                      "watts/person": "power_per_person"}
               for kind in ("GasEquipment", "HotWaterEquipment", "SteamEquipment", "OtherEquipment")}
GAIN_FIELDS["ElectricEquipment"] = {"equipmentlevel": "design_level", "watts/area": "watts_per_zone_floor_area",
                                    "watts/person": "watts_per_person"}
GAIN_FIELDS["Lights"] = {"lightinglevel": "lighting_level", "watts/area": "watts_per_zone_floor_area",
                         "watts/person": "watts_per_person"}
FLOWS = ("ZoneInfiltration:DesignFlowRate", "ZoneVentilation:DesignFlowRate")
# The shading objects the building file holds as shading polygons (`_Converter.shading`)
SHADING = ("Shading:Site:Detailed", "Shading:Building:Detailed", "Shading:Zone:Detailed", "Shading:Site",
           "Shading:Building", "Shading:Overhang", "Shading:Overhang:Projection", "Shading:Fin",
           "Shading:Fin:Projection")
SCHEDULES = ("Schedule:Compact", "Schedule:Constant", "Schedule:Year", "Schedule:Week:Daily",
             "Schedule:Week:Compact", "Schedule:Day:Interval", "Schedule:Day:Hourly", "Schedule:Day:List",
             "ScheduleTypeLimits")
READ = set(("Version", "Site:Location", "GlobalGeometryRules", "Building", "Zone", "ZoneList", "Space", "SpaceList",
            "Construction",
            "Material", "Material:NoMass", "Material:AirGap", "Material:InfraredTransparent", "Material:RoofVegetation",
            "WindowMaterial:Glazing", "WindowMaterial:Glazing:RefractionExtinctionMethod",
            "WindowMaterial:GlazingGroup:Thermochromic", "WindowMaterial:Gas",
            "WindowMaterial:SimpleGlazingSystem", "Site:GroundTemperature:BuildingSurface",
            "Site:GroundTemperature:Deep", "Timestep",
            "InternalMass", "Construction:FfactorGroundFloor", "Construction:CfactorUndergroundWall",
            "Construction:WindowDataFile", "Construction:AirBoundary", "SurfaceProperty:IncidentSolarMultiplier",
            "Site:GroundTemperature:FCfactorMethod", "SurfaceProperty:OtherSideCoefficients",
            "SurfaceProperty:OtherSideConditionsModel", "WindowMaterial:GasMixture", "MaterialProperty:GlazingSpectralData", "RunPeriodControl:SpecialDays", "SurfaceConvectionAlgorithm:Inside", "SurfaceConvectionAlgorithm:Outside") + SURFACES + tuple(SIMPLE_SURFACES) + SUBSURFACES + GAINS + FLOWS + SCHEDULES + SHADING)
# Objects about the run and its reports, not the building
# ... but these run objects change what the building sees, and are listed
LISTED_RUN = ("RunPeriodControl:DaylightSavingTime",)
NOT_PHYSICS = ("Output", "OutputControl", "LifeCycleCost", "Meter", "RunPeriod", "SimulationControl", "Sizing:Parameters",
               "UtilityCost", "ComponentCost", "CurrencyType")


def newest_schema():
    """The newest EnergyPlus version whose IDD idfkit holds, (major, minor, patch)."""
    import idfkit.schema
    return max(idfkit.schema.get_schema_manager().get_available_versions())


def load_idf(path):
    """The idfkit document of an IDF; InputError naming the file for one that cannot be read."""
    import idfkit
    text = closed_text(path)
    try:
        version = idfkit.get_idf_version(str(path))
    except Exception as e:
        raise InputError(path, "Version", f"no EnergyPlus version could be read ({e})") from None
    if version is None:
        raise InputError(path, "Version", "the file has no Version object")
    newest = newest_schema()
    if tuple(version[:2]) > tuple(newest[:2]):
        raise InputError(path, "Version", f"EnergyPlus {'.'.join(map(str, version[:2]))} is newer than any IDD the "
                                          f"converter holds (idfkit's newest: {'.'.join(map(str, newest[:2]))})")
    override = None
    if tuple(version[:2]) < SCHEMA_MIN[:2]:
        if tuple(version[:2]) < MIN_VERSION:
            raise InputError(path, "Version", f"EnergyPlus {'.'.join(map(str, version[:2]))} is older than 8.4: "
                                              "bring the file to a later version (EnergyPlus's IDFVersionUpdater)")
        override = SCHEMA_MIN
    try:
        if override is None or not _OTHER_EQUIPMENT.search(_code(text)):
            return idfkit.load_idf(str(path), version=override)
        with tempfile.TemporaryDirectory() as tmp:
            moved = Path(tmp) / "model.idf"
            moved.write_text(to_schema_min(text), encoding="utf-8")
            return idfkit.load_idf(str(moved), version=override)
    except Exception as e:
        message = str(e).splitlines()[0] if str(e) else type(e).__name__
        raise InputError(path, "(file)", f"not a readable IDF: {message}") from None


def _code(text):
    """An IDF's text without its comments."""
    return "\n".join(line.split("!", 1)[0] for line in text.splitlines())


# an OtherEquipment object up to the comma after its name (its fields counted past comments)
_OTHER_EQUIPMENT = re.compile(r"(?i)((?:^|;)\s*OtherEquipment\s*,[^,;]*,)")


def to_schema_min(text):
    """The text of an 8.4 to 8.8 file for 8.9's IDD, which it is read against: of the objects the
    converter reads, only OtherEquipment changed its fields, 8.9 inserting `Fuel Type` after the
    name (EnergyPlus's 8.8 to 8.9 transition fills it with None, as here); comments dropped."""
    return _OTHER_EQUIPMENT.sub(lambda m: m.group(1) + " None,", _code(text))


# The version whose IDD names the fields this module asks for; a file of another version has its
# fields found by aligning that version's IDD field list with this one's (`_field_names`)
REFERENCE_SCHEMA = (8, 9, 0)


def _idd_fields(obj_type, version):
    """The IDD's fields of an object type in an EnergyPlus version, in order ([] for an unknown type)."""
    import idfkit.schema
    schema = idfkit.schema.get_schema(tuple(version))
    obj = schema.get_object_schema(obj_type) if obj_type in schema else None
    return list(obj["legacy_idd"]["fields"]) if obj else []


def _words(name):
    return set(name.split("_"))


@functools.lru_cache(maxsize=None)
def _field_names(obj_type, version):
    """{reference name: name in `version`} of an object type's fields, found through the two
    versions' IDDs (idfkit's schemas), not a table of renames: their field lists aligned (difflib),
    a field kept where it was, a renamed one the field at its place (a run of renamed fields of
    equal length, field by field; else the field sharing most words with it, as `Zone Name` ->
    `Zone or ZoneList Name` beside an inserted `Space or SpaceList Name`)."""
    ref, own = _idd_fields(obj_type, REFERENCE_SCHEMA), _idd_fields(obj_type, version)
    out = {n: n for n in own}
    matcher = difflib.SequenceMatcher(None, ref, own, autojunk=False)
    for tag, i1, i2, j1, j2 in matcher.get_opcodes():
        if tag != "replace":
            continue
        if i2 - i1 == j2 - j1:
            out.update({ref[i]: own[j1 + i - i1] for i in range(i1, i2) if ref[i] not in out})
            continue
        for i in range(i1, i2):
            best = max(own[j1:j2], key=lambda n: len(_words(n) & _words(ref[i])) / len(_words(n) | _words(ref[i])))
            if _words(best) & _words(ref[i]) - {"name"} and ref[i] not in out:
                out[ref[i]] = best
    return out


def _version_of(obj):
    """The version whose IDD an object is read by: its file's, or for a file of 8.4 to 8.8 (no IDD
    of which idfkit holds) 8.9's, the IDD `_load` reads it against."""
    doc = getattr(obj, "theidf", None)
    version = getattr(doc, "version", None)
    if not version:
        return REFERENCE_SCHEMA
    return max(tuple(version), SCHEMA_MIN)


def _own_name(obj, field):
    """A field's name in the IDD of the object's own version."""
    return _field_names(obj.obj_type, _version_of(obj)).get(field, field)


def _field(obj, field):
    """A field's value, the field named as the reference version's IDD names it and found in the
    object's own version's (`_field_names`); None where the object's type has no such field."""
    return obj.to_dict().get(_own_name(obj, field))


def _field_label(obj, field):
    """A field's name as the IDD of the object's own version writes it (`Watts per Floor Area`)."""
    import idfkit.schema
    own = _own_name(obj, field)
    try:
        info = idfkit.schema.get_schema(_version_of(obj)).get_object_schema(obj.obj_type)["legacy_idd"]["field_info"]
        return info[own]["field_name"]
    except (KeyError, TypeError):
        return _label(field)


def _autocalculated(value):
    """A field EnergyPlus computes: blank, Autocalculate (or Autosize), or 0 or less (which it reads
    so for a zone's volume, floor area and ceiling height)."""
    if _blank(value) or str(value).strip().lower() in ("autocalculate", "autosize"):
        return True
    try:
        return float(value) <= 0.0  # and a negative one, as -9999 in some reference buildings
    except (TypeError, ValueError):
        return False


def geometry_closed(polygons, counterclockwise=True, tolerance=0.01):
    """Whether polygons close a volume: their area-weighted outward normals sum to less than
    `tolerance` of their total area (a closed polyhedron's sum to zero)."""
    total = sum(geometry.area(p) for p in polygons)
    flux = sum(geometry.area(p) * geometry.outward_normal(p, counterclockwise) for p in polygons)
    return total > 0 and float(np.linalg.norm(flux)) < tolerance * total


def _blank(value):
    return value is None or (isinstance(value, str) and value.strip() == "")


class _Reader:
    """The document's objects by type and name, and fields that fail with the file and object."""

    def __init__(self, doc, source):
        self.doc, self.source = doc, source
        self.by_name = {}
        for obj in doc.all_objects:
            self.by_name.setdefault(obj.obj_type.upper(), {})[str(getattr(obj, "name", "") or "").upper()] = obj

    def all(self, kind):
        return [o for o in self.doc.all_objects if o.obj_type.upper() == kind.upper()]

    def get(self, kinds, name, referrer, field):
        for kind in ((kinds,) if isinstance(kinds, str) else kinds):
            obj = self.by_name.get(kind.upper(), {}).get(str(name).upper())
            if obj is not None:
                return obj
        self.fail(referrer, field, f"names no {' or '.join((kinds,) if isinstance(kinds, str) else kinds)} ({name!r})")

    def fail(self, obj, field, problem):
        where = f"{obj.obj_type} {getattr(obj, 'name', '')!r}".strip() if obj is not None else "(file)"
        raise InputError(self.source, f"{where}, field {field}", problem)

    def number(self, obj, field, default=None, low=None, low_open=False, high=None):
        value = _field(obj, field)
        if _blank(value):
            if default is None:
                self.fail(obj, _field_label(obj, field), "missing: a number is needed")
            return float(default)
        if isinstance(value, str):
            if value.strip().lower() in ("autocalculate", "autosize"):
                self.fail(obj, _field_label(obj, field), f"{value}: the converter needs the number")
            try:
                value = float(value)
            except ValueError:
                self.fail(obj, _field_label(obj, field), f"{value!r} is not a number")
        value = float(value)
        if low is not None and (value <= low if low_open else value < low):
            self.fail(obj, _field_label(obj, field), f"{value:g} must be {'>' if low_open else '>='} {low:g}")
        if high is not None and value > high:
            self.fail(obj, _field_label(obj, field), f"{value:g} must be <= {high:g}")
        return value

    def text(self, obj, field, default=""):
        value = _field(obj, field)
        return default if _blank(value) else str(value).strip()


def _label(field):
    """An idfkit field name as EnergyPlus's documentation writes it."""
    return " ".join(w.capitalize() for w in field.split("_"))


def convert(path):
    """The building file's JSON (a dict) of the EnergyPlus model at `path`; InputError for an IDF
    the conversion cannot read (docs/guide.md lists each refusal)."""
    doc = load_idf(path)
    return _Converter(_Reader(doc, str(path))).building()


# EnergyPlus's equivalent construction of an F- or C-factor (Engineering Reference, "Ground Heat
# Transfer Calculations using C and F Factor Constructions"; HeatBalanceManager's
# CreateFCfactorConstructions): 6 in of heavy concrete behind a fictitious massless layer
FC_CONCRETE = "~FC_Concrete"
FC_CONCRETE_PROPERTIES = (0.15, 1.95, 2240.0, 900.0)  # m, W/m/K, kg/m3, J/kg/K
FC_FILM_INSIDE, FC_FILM_OUTSIDE = 0.135, 0.03  # m2K/W, the films an F-factor includes
FC_MIN_RESISTANCE = 0.001  # m2K/W, the least fictitious layer EnergyPlus accepts
FC_NO_PERIMETER = 1000.0  # m2K/W, a floor with no exposed perimeter loses nothing to the ground's edge


def ffactor_fictitious_resistance(F, area, perimeter):
    """The fictitious layer (m2K/W) of an F-factor floor: its effective resistance A / (P F), F in
    W/m/K, A in m2, P the exposed perimeter in m, less the concrete and the two films it includes."""
    if perimeter <= 0:
        return FC_NO_PERIMETER
    R_eff = area / (perimeter * F)
    R_concrete = FC_CONCRETE_PROPERTIES[0] / FC_CONCRETE_PROPERTIES[1]
    return max(FC_MIN_RESISTANCE, R_eff - R_concrete - FC_FILM_INSIDE - FC_FILM_OUTSIDE)


def cfactor_fictitious_resistance(C, height):
    """The fictitious layer (m2K/W) of a C-factor underground wall of `height` m: 1/C (W/m2/K,
    films excluded) plus the soil's equivalent resistance 0.0607 + 0.3479 H (Engineering Reference,
    eq. 3.195), less the concrete."""
    R_eff = 1.0 / C + 0.0607 + 0.3479 * height
    return max(FC_MIN_RESISTANCE, R_eff - FC_CONCRETE_PROPERTIES[0] / FC_CONCRETE_PROPERTIES[1])


def read_window5(text, window):
    """The first glazing system of a window in a WINDOW 5 data file (EnergyPlus's
    Window5DataFile.dat format): {"panes": [{thickness m, conductivity, T, R_front, R_back,
    emissivity_front, emissivity_back}], "gaps": [{thickness m, gas}]}, a gap's gas its gases'
    own coefficients as `model.glazing.gas_properties` reads them, mole fractions for a mixture.
    ValueError naming what is missing."""
    blocks = re.split(r"(?im)^\s*Window name\s*:", text)[1:]
    block = next((b for b in blocks if b.splitlines()[0].strip().upper() == window.strip().upper()), None)
    if block is None:
        raise ValueError(f"no window named {window!r} in the file")
    lines = block.splitlines()

    def rows_after(title):
        """The value rows of a section: its first row after 'System1 :', continuation rows after."""
        start = next((i for i, line in enumerate(lines) if line.strip().upper().startswith(title)), None)
        if start is None:
            raise ValueError(f"window {window!r} has no {title}")
        out = []
        for line in lines[start + 1:]:
            body = line.split(":", 1)[1] if ":" in line else line
            head = line.split(":", 1)[0].strip() if ":" in line else ""
            if ":" in line and not head.upper().startswith("SYSTEM1"):
                break
            if not body.strip() or not re.match(r"^\s*[-0-9.]", body):
                break
            out.append(body.split())
        return out

    try:
        (system,) = rows_after("GLAZING SYSTEM DATA")[:1]
        n = int(system[2])
        glass = rows_after("GLASS DATA")[:n]
        panes = [{"thickness": float(r[1]) / 1000, "conductivity": float(r[2]), "T": float(r[3]),
                  "R_front": float(r[4]), "R_back": float(r[5]), "emissivity_front": float(r[10]),
                  "emissivity_back": float(r[11])} for r in glass]
        gaps = []
        if n > 1:
            gap_rows = rows_after("GAP DATA")[:n - 1]
            gas_rows = [line.split(":", 1)[1].split() for line in lines
                        if re.match(r"(?i)^\s*System1\s+Gap\d+\s*:", line)]
            for k, r in enumerate(gap_rows):
                rows = [g for line, g in zip([ln for ln in lines if re.match(r"(?i)^\s*System1\s+Gap\d+\s*:", ln)],
                                             gas_rows) if re.match(rf"(?i)^\s*System1\s+Gap{k + 1}\s*:", line)]
                if len(rows) != int(r[2]):
                    raise ValueError(f"gap {k + 1} of window {window!r} lists {len(rows)} gases, not {r[2]}")
                # conductivity in W/m/K, viscosity in g/m/s and specific heat in kJ/kg/K (air's
                # at 300 K: 0.026, 0.0185 and 1.006), brought to SI as gas_properties reads them
                gases = [((tuple(map(float, g[3:6])), tuple(1e-3 * float(v) for v in g[6:9]),
                           tuple(1e3 * float(v) for v in g[9:12]), float(g[2])), float(g[1])) for g in rows]
                gaps.append({"thickness": float(r[1]) / 1000, "gas": gases[0][0] if len(gases) == 1 else gases})
    except (IndexError, ValueError) as e:
        raise ValueError(str(e) if isinstance(e, ValueError) and str(e).startswith(("gap", "window"))
                         else f"window {window!r}: a glazing, glass or gap row is incomplete") from None
    if len(panes) != n or len(gaps) != n - 1:
        raise ValueError(f"window {window!r}: {n} panes declared, {len(panes)} glass and {len(gaps)} gap rows")
    return {"panes": panes, "gaps": gaps}


# Constructions the building file cannot hold, with why
UNREAD_CONSTRUCTIONS = {
    "Construction:WindowEquivalentLayer": "an equivalent-layer window is not read (give its layers)",
    "Construction:ComplexFenestrationState": "a BSDF window is not read (give its layers)",
}


# idfkit's names of the days of the week, Monday first as `date.weekday` counts them
_WEEKDAYS = ("Monday", "Tuesday", "Wednesday", "Thursday", "Friday", "Saturday", "Sunday")

# The day types of a Schedule:Compact's "For:" field, each word singular or plural as EnergyPlus
# reads it ("For: Weekday" is Monday to Friday; idfkit knows only some of the plurals, and the
# 2019 prototypes' lighting schedules are written "Weekday")
_FOR_WORDS = {"weekday": "Weekdays", "weekend": "Weekends", "allday": "AllDays", "allotherday": "AllOtherDays",
              "holiday": "Holiday", "summerdesignday": "SummerDesignDay", "winterdesignday": "WinterDesignDay",
              "customday1": "CustomDay1", "customday2": "CustomDay2",
              **{d.lower(): d for d in _WEEKDAYS}}


def compact_day_types(text):
    """The day types (idfkit's names) of a Schedule:Compact "For:" field `text`, as EnergyPlus
    reads them: words split by spaces or commas, each singular or plural, case aside. A word that
    is no day type names no day, as idfkit has it (the 2019 small office's "Weedends", in a
    schedule of its HVAC, which EnergyPlus runs)."""
    types = set()
    for word in re.split(r"[\s,]+", text.split(":", 1)[1].strip().lower()):
        key = word[:-1] if word.endswith("s") and word[:-1] in _FOR_WORDS else word
        if key in _FOR_WORDS:
            types.add(_FOR_WORDS[key])
    return types


def _compact_periods(obj):
    """idfkit's periods and interpolation of a Schedule:Compact, each rule's day types read as
    EnergyPlus reads them (`compact_day_types`): each "For:" field makes one rule, in order."""
    from dataclasses import replace
    from idfkit.schedules import compact
    periods, interpolation = compact.parse_compact(obj)
    fields = [str(item.get("field") or "").strip() for item in obj.data.get("data") or []]
    days = iter([compact_day_types(f) for f in fields if f.lower().startswith("for:")])
    return [replace(p, day_rules=[replace(r, day_types=next(days)) for r in p.day_rules]) for p in periods], interpolation


def day_types_of(d, holidays, custom_day_1, custom_day_2):
    """The day types (idfkit's names) a "For:" field or a week's day list must name to apply on
    the date `d`: EnergyPlus gives a date one day type, a special day's (CustomDay2, CustomDay1,
    Holiday, in idfkit's order of precedence) in place of its day of the week's, and "Weekdays"
    or "Weekends" only to days that are no special day. idfkit's `get_applicable_day_types` adds
    the day of the week to a special day's, so a Tuesday holiday took "For: Weekdays" where
    EnergyPlus takes "For: AllOtherDays" (the 2004 reference offices' and schools' gains)."""
    for days, special in ((custom_day_2, "CustomDay2"), (custom_day_1, "CustomDay1"), (holidays, "Holiday")):
        if d in days:
            return {special, "AllDays", "AllOtherDays"}
    weekday = d.weekday()
    return {_WEEKDAYS[weekday], "Weekdays" if weekday < 5 else "Weekends",
            "AllDays", "AllOtherDays"}


class _DaySchedules:
    """A schedule's values over the year `YEAR` on a time step, by idfkit's functions but day by
    day: the document's holidays and special days found once (idfkit's `values` finds them again at
    every time step, some 40 s a schedule of a DOE reference building), each date's day types
    EnergyPlus's (`day_types_of`), and each day profile evaluated once, the days that share it
    copied."""

    def __init__(self, doc):
        from idfkit.schedules.holidays import get_holidays, get_special_days_by_type
        self.doc = doc
        self.special = (get_holidays(doc, YEAR), get_special_days_by_type(doc, YEAR, "CustomDay1"),
                        get_special_days_by_type(doc, YEAR, "CustomDay2"))
        self.profiles = {}

    def dates(self):
        import datetime
        first = datetime.date(YEAR, 1, 1)
        return [first + datetime.timedelta(days=k) for k in range((datetime.date(YEAR + 1, 1, 1) - first).days)]

    def times(self, ts):
        import datetime
        return [datetime.time(h, m * 60 // ts) for h in range(24) for m in range(ts)]

    def of(self, obj, ts):
        """(days, 24 ts) values of a Schedule:Compact, Schedule:Constant or Schedule:Week:Daily/Compact."""
        from idfkit.schedules import compact, week
        from idfkit.schedules.time_utils import evaluate_time_values
        from idfkit.schedules.types import DayType
        kind = obj.obj_type.upper()
        if kind == "SCHEDULE:CONSTANT":
            value = self.day_values(obj, ts)[0]
            return np.full((len(self.dates()), 24 * ts), value)
        rows = []
        if kind == "SCHEDULE:COMPACT":
            periods, interpolation = _compact_periods(obj)
            for d in self.dates():
                period = compact._find_period_for_date(periods, d) if periods else None
                rule = None if period is None else compact._find_matching_rule(
                    period.day_rules, day_types_of(d, *self.special))
                key = ("rule", id(rule), ts)
                if key not in self.profiles:
                    self.profiles[key] = (np.zeros(24 * ts) if rule is None else np.array(
                        [evaluate_time_values(rule.time_values, t, interpolation) for t in self.times(ts)]), rule)
                rows.append(self.profiles[key][0])
            return np.array(rows, dtype=float)
        for d in self.dates():
            if kind == "SCHEDULE:WEEK:DAILY":
                day_name = week._get_day_schedule_name_for_date(obj, d, DayType.NORMAL, *self.special)
            else:
                day_name = week._find_matching_day_in_week_compact(
                    obj, day_types_of(d, *self.special))
            if day_name is None:
                rows.append(np.zeros(24 * ts))
                continue
            day = week._find_day_schedule(self.doc, day_name)
            if day is None:
                raise ValueError(f"Day schedule not found: {day_name!r}")
            rows.append(self.day_values(day, ts))
        return np.array(rows, dtype=float)

    def day_values(self, day, ts):
        from idfkit.schedules.day import get_day_values
        key = ("day", day.obj_type.upper(), str(day.name).upper(), ts)
        if key not in self.profiles:
            self.profiles[key] = (np.asarray(get_day_values(day, ts), dtype=float), day)
        return self.profiles[key][0]


def _json_gas(gas):
    """A gap's gas (`Converter.gas`, `read_window5`) as a building file's window declares it: a
    name, a mixture of named gases [[gas, fraction], ...], or a gas of its own {conductivity,
    viscosity, specific_heat, molecular_weight}; None for a mixture of gases of their own, which
    the file cannot declare."""
    if isinstance(gas, str):
        return gas
    if isinstance(gas, list):
        return [[g, x] for g, x in gas] if all(isinstance(g, str) for g, _ in gas) else None
    k, mu, cp, M = gas
    return {"conductivity": list(k), "viscosity": list(mu), "specific_heat": list(cp), "molecular_weight": M}


class _Converter:
    def __init__(self, reader):
        self.r = reader
        self._days = _DaySchedules(reader.doc)
        self.materials = {}
        self.constructions = {}  # CONSTRUCTION NAME -> (its name as first written, [component names])
        self.schedules = {}
        self.not_modelled = []
        self.notes = []

    def note(self, text):
        """An assumption the file's description states, once."""
        if text not in self.notes:
            self.notes.append(text)

    # ---- site, rules, schedules ---------------------------------------------------------
    def site(self):
        locations = self.r.all("Site:Location")
        if not locations:
            self.r.fail(None, "Site:Location", "missing: the sun's position needs the site")
        loc = locations[0]
        zone_h = self.r.number(loc, "time_zone", low=-12, high=14)
        hours, minutes = int(abs(zone_h)), int(round(abs(zone_h) % 1 * 60))
        if minutes == 0:
            tz = "UTC" if hours == 0 else f"Etc/GMT{'-' if zone_h > 0 else '+'}{hours}"
        else:
            tz = f"{'+' if zone_h >= 0 else '-'}{hours:02d}:{minutes:02d}"
        altitude = self.r.number(loc, "elevation", default=0.0, low=-300, high=8000)
        site = {"latitude": self.r.number(loc, "latitude", low=-90, high=90),
                "longitude": self.r.number(loc, "longitude", low=-180, high=180),
                "altitude": altitude, "timezone": tz, "air_density": round(air_density_at(altitude), 5),
                # EnergyPlus carries infiltration and ventilation at the outdoor air's density
                "flow_density": "outdoor",
                # its anisotropic sky (SolarShading.cc, AnisoSkyViewFactors) and its sun's daily
                # series (WeatherManager.cc, CalculateDailySolarCoeffs), whatever the IDF says
                "sky_diffuse": "energyplus", "solar_position": "energyplus"}
        # the deep ground's months average to the temperature a diagnosis holds a ground
        # coupling's at where the data fix its flux only (docs/model.md section 7, Priors)
        deep = self.r.all("Site:GroundTemperature:Deep")
        if deep:
            site["ground_temperature"] = float(np.mean(
                [self.r.number(deep[0], f"{m}_deep_ground_temperature", default=DEFAULT_DEEP_GROUND, low=-60, high=60)
                 for m in MONTHS]))
        return site

    def geometry_rules(self):
        rules = self.r.all("GlobalGeometryRules")
        if not rules:
            self.r.fail(None, "GlobalGeometryRules", "missing: the vertices' order and coordinates need it")
        g = rules[0]
        direction = self.r.text(g, "vertex_entry_direction", "Counterclockwise").lower()
        if direction not in ("counterclockwise", "clockwise"):
            self.r.fail(g, "Vertex Entry Direction", f"{direction!r} is neither Counterclockwise nor Clockwise")
        system = self.r.text(g, "coordinate_system", "Relative").lower()
        rect = self.r.text(g, "rectangular_surface_coordinate_system", "Relative").lower()
        buildings = self.r.all("Building")
        north = self.r.number(buildings[0], "north_axis", default=0.0) if buildings else 0.0
        self.ccw, self.relative, self.rect_relative, self.north = (
            direction == "counterclockwise", system == "relative", rect == "relative", north)
        terrain = self.r.text(buildings[0], "terrain", "Suburbs").lower() if buildings else "suburbs"
        if terrain not in convection.TERRAIN:
            self.r.fail(buildings[0], "Terrain", f"{terrain!r} is none of EnergyPlus's terrains")
        self.terrain = terrain
        inside = self.r.all("SurfaceConvectionAlgorithm:Inside")
        self.default_inside = self.r.text(inside[0], "algorithm", "TARP") if inside else "TARP"
        outside = self.r.all("SurfaceConvectionAlgorithm:Outside")
        algorithm = self.r.text(outside[0], "algorithm", "DOE-2") if outside else "DOE-2"
        self.notes.append(f"outside convection EnergyPlus's DOE-2 from each hour's wind and each face's temperature, "
                          f"its value at a {FILMS.wind:g} m/s station wind and a {FILMS.delta_T:g} K face-to-air "
                          "difference in the step matrix" +
                          ("" if algorithm.lower() == "doe-2" else f" (the IDF's {algorithm} evaluated as DOE-2)"))
        self.notes.append(f"outside long-wave toward the sky, the air and the ground from each step's face and sky "
                          f"temperatures, its value at {FILMS.T_outside - 273.15:g} C in the step matrix")

    def inside_algorithm(self, zone_name):
        """'simple' or 'tarp': the zone's inside convection algorithm (its own field, else the
        IDF's SurfaceConvectionAlgorithm:Inside); any other is evaluated as TARP, and said so."""
        zone = self.zone_objs[zone_name.upper()]
        algorithm = self.r.text(zone, "zone_inside_convection_algorithm", "") or self.default_inside
        if algorithm.lower() not in ("simple", "tarp"):
            note = f"the inside convection algorithm {algorithm} evaluated as TARP"
            if note not in self.notes:
                self.notes.append(note)
            return "tarp"
        return algorithm.lower()

    def schedule(self, name, referrer, field):
        """The building file's name of an IDF schedule, converted once (its values over a year on
        the IDF's time step, as day profiles by date and day of the week)."""
        if name in self.schedules:
            return name
        obj = self.r.get(("Schedule:Compact", "Schedule:Constant", "Schedule:Year"), name, referrer, field)
        ts = self.timesteps
        try:
            if obj.obj_type.upper() == "SCHEDULE:YEAR":
                values = self._year_values(obj, ts)
            else:
                values = self._days.of(obj, ts).ravel()
        except InputError:
            raise
        except Exception as e:
            self.r.fail(obj, "(values)", f"could not be evaluated ({str(e).splitlines()[0] if str(e) else type(e).__name__})")
        self.schedules[name] = compress_schedule(values.reshape(-1, 24 * ts), YEAR)
        return name

    def _year_values(self, obj, ts):
        """A Schedule:Year's values: each week schedule over its dates (idfkit reads the weeks)."""
        import datetime
        days = (datetime.date(YEAR + 1, 1, 1) - datetime.date(YEAR, 1, 1)).days
        out = np.full((days, 24 * ts), np.nan)
        fields = obj.to_dict()
        weeks = fields.get("schedule_weeks")
        if not isinstance(weeks, list):  # the fields as numbered in the IDD
            weeks, k = [], 1
            while not _blank(fields.get(f"schedule_week_name_{k}")):
                weeks.append({f: fields.get(f"{f}_{k}") for f in ("schedule_week_name", "start_month", "start_day",
                                                                   "end_month", "end_day")})
                k += 1
        for k, w in enumerate(weeks, start=1):
            week = self.r.get(("Schedule:Week:Daily", "Schedule:Week:Compact"), w["schedule_week_name"],
                              obj, f"Schedule:Week Name {k}")
            try:
                start = datetime.date(YEAR, int(float(w["start_month"])), int(float(w["start_day"])))
                end = datetime.date(YEAR, int(float(w["end_month"])), int(float(w["end_day"])))
            except (TypeError, ValueError) as e:
                self.r.fail(obj, f"Start Month {k}", f"not a date ({e})")
            values = self._days.of(week, ts)
            first, last = (start - datetime.date(YEAR, 1, 1)).days, (end - datetime.date(YEAR, 1, 1)).days
            out[first:last + 1] = values.reshape(-1, 24 * ts)[first:last + 1]
        if np.isnan(out).any():
            self.r.fail(obj, "Start Month", "the weeks do not cover every day of the year")
        return out.ravel()

    def constant_schedule_value(self, name, referrer, field):
        """The one value of a schedule that has one (None if it varies)."""
        s = self.schedules[self.schedule(name, referrer, field)]
        return s["constant"] if "constant" in s else None

    def monthly_schedule(self, name, kind, default):
        """A schedule of an object's twelve monthly temperatures (C), once."""
        if name not in self.schedules:
            obj = self.r.all(kind)[0]
            temps = [self.r.number(obj, f"{m}_ground_temperature", default=default) for m in MONTHS]
            self.schedules[name] = monthly(temps)
        return name

    def ground_schedule(self):
        if "ground temperature" in self.schedules:
            return "ground temperature"
        objs = self.r.all("Site:GroundTemperature:BuildingSurface")
        if objs:
            temps = [self.r.number(objs[0], f"{m}_ground_temperature", default=DEFAULT_GROUND) for m in MONTHS]
        else:
            temps = [DEFAULT_GROUND] * 12
            self.notes.append(f"no Site:GroundTemperature:BuildingSurface: the ground is at EnergyPlus's default "
                              f"{DEFAULT_GROUND:g} C all year")
        self.schedules["ground temperature"] = monthly(temps)
        return "ground temperature"

    # ---- constructions -----------------------------------------------------------------
    def layers(self, construction_name, referrer, field, height=None):
        """(layers outside first as [[material, thickness]], outer Layer info, inner Layer info,
        glazing or None) of a Construction."""
        for kind, equivalent in (("Construction:FfactorGroundFloor", self.ffactor_layers),
                                 ("Construction:CfactorUndergroundWall", self.cfactor_layers)):
            c = self.r.by_name.get(kind.upper(), {}).get(str(construction_name).upper())
            if c is not None:
                return equivalent(c)
        c = self.r.by_name.get("CONSTRUCTION:WINDOWDATAFILE", {}).get(str(construction_name).upper())
        if c is not None:
            return self.window_data_file(c, height)
        for kind in UNREAD_CONSTRUCTIONS:
            c = self.r.by_name.get(kind.upper(), {}).get(str(construction_name).upper())
            if c is not None:
                self.r.fail(referrer, field, f"{construction_name!r} is a {kind}: {UNREAD_CONSTRUCTIONS[kind]}")
        c = self.r.get(("Construction", "Construction:InternalSource"), construction_name, referrer, field)
        names = [v for v in c.to_dict().values()][1:]
        if c.obj_type.upper() == "CONSTRUCTION:INTERNALSOURCE":
            fields = c.to_dict()
            names = [fields.get("outside_layer")] + [fields.get(f"layer_{k}") for k in range(2, 11)]
            line = f"Construction:InternalSource {c.name}: its layers read, its heat source not held"
            if line not in self.not_modelled:
                self.not_modelled.append(line)
        names = [n for n in names if not _blank(n)]
        if not names:
            self.r.fail(c, "Outside Layer", "missing: a construction needs a layer")
        kinds = ("Material", "Material:NoMass", "Material:AirGap", "Material:InfraredTransparent",
                 "Material:RoofVegetation", "WindowMaterial:Glazing", "WindowMaterial:Glazing:RefractionExtinctionMethod",
                 "WindowMaterial:GlazingGroup:Thermochromic", "WindowMaterial:Gas", "WindowMaterial:GasMixture",
                 "WindowMaterial:SimpleGlazingSystem")
        objs = []
        for k, n in enumerate(names):
            for kind in kinds:
                obj = self.r.by_name.get(kind.upper(), {}).get(n.upper())
                if obj is not None:
                    break
            if obj is None:
                self.r.fail(c, "Outside Layer" if k == 0 else f"Layer {k + 1}",
                            f"names no material this converter reads ({n!r}; it reads {', '.join(kinds)})")
            if obj.obj_type.upper() == "WINDOWMATERIAL:GLAZINGGROUP:THERMOCHROMIC":
                obj = self.thermochromic_pane(obj)
            self._approximated_material(obj)
            objs.append(obj)
        window = [o.obj_type.upper().startswith("WINDOWMATERIAL") for o in objs]
        if any(window) and not all(window):
            self.r.fail(c, "Outside Layer", "mixes window and opaque materials")
        if all(window):
            return self.glazing_layers(c, objs, height)
        layers = [[self.opaque_material(o), self._thickness(o)] for o in objs]
        return layers, self._faces(objs[0]), self._faces(objs[-1]), None

    def _fc_concrete(self):
        self.materials.setdefault(FC_CONCRETE, {"conductivity": FC_CONCRETE_PROPERTIES[1], "density": FC_CONCRETE_PROPERTIES[2],
                                                "specific_heat": FC_CONCRETE_PROPERTIES[3]})
        return [FC_CONCRETE, FC_CONCRETE_PROPERTIES[0]]

    def _fc_layers(self, c, R_fic):
        """EnergyPlus's equivalent construction: a fictitious massless layer of R_fic outside 0.15 m
        of heavy concrete (HeatBalanceManager, CreateFCfactorConstructions)."""
        name = f"{c.name} (fictitious R {R_fic:.4g})"
        self.materials[name] = {"conductivity": MASSLESS_THICKNESS / R_fic, "density": 0.0, "specific_heat": 0.0}
        faces = {"emissivity": 0.9, "solar": 0.7, "roughness": convection.ROUGHNESS["mediumrough"]}
        return [[name, MASSLESS_THICKNESS], self._fc_concrete()], faces, faces, None

    def ffactor_layers(self, c):
        F = self.r.number(c, "f_factor", low=0, low_open=True)
        area = self.r.number(c, "area", low=0, low_open=True)
        perimeter = self.r.number(c, "perimeterexposed", low=0)
        return self._fc_layers(c, ffactor_fictitious_resistance(F, area, perimeter))

    def cfactor_layers(self, c):
        C = self.r.number(c, "c_factor", low=0, low_open=True)
        height = self.r.number(c, "height", low=0)
        return self._fc_layers(c, cfactor_fictitious_resistance(C, height))

    def thermochromic_pane(self, group):
        """The WindowMaterial:Glazing of a thermochromic group at the optical data temperature
        nearest THERMOCHROMIC_T (the group's pane at 20 C where it has one, its coolest where all
        are warmer): the building file's panes do not change with their temperature."""
        fields = group.to_dict()
        rows = list(next((v for v in fields.values() if isinstance(v, list)), []))  # its extensible group
        k = 1
        while f"optical_data_temperature_{k}" in fields:  # the fields as numbered in the IDD
            rows.append({f: fields.get(f"{f}_{k}") for f in ("optical_data_temperature", "window_material_glazing_name")})
            k += 1
        try:
            rows = [(float(r["optical_data_temperature"]), str(r["window_material_glazing_name"])) for r in rows
                    if not _blank(r.get("window_material_glazing_name"))]
        except (KeyError, TypeError, ValueError):
            self.r.fail(group, "Optical Data Temperature 1", "a temperature is not a number")
        if not rows:
            self.r.fail(group, "Window Material Glazing Name 1", "missing: a thermochromic group needs a pane")
        T, name = min(rows, key=lambda row: (abs(row[0] - THERMOCHROMIC_T), row[0]))
        line = (f"WindowMaterial:GlazingGroup:Thermochromic {group.name}: its pane at {T:g} C ({name}) at every "
                "temperature; the switching of its optics with the pane's temperature not held")
        if line not in self.not_modelled:
            self.not_modelled.append(line)
        return self.r.get("WindowMaterial:Glazing", name, group, "Window Material Glazing Name")

    def _approximated_material(self, o):
        """List once what a material EnergyPlus reads beyond the building file's layers carries."""
        kind = o.obj_type.upper()
        text = {"MATERIAL:INFRAREDTRANSPARENT": "a massless layer of resistance 0.01 m2K/W, as EnergyPlus holds it; "
                                                "the long-wave radiation it lets cross between the zones not held",
                "MATERIAL:ROOFVEGETATION": "its soil layer, of the dry soil's properties; the plants' shading and "
                                           "evapotranspiration and the soil's moisture not held"}.get(kind)
        line = f"{o.obj_type} {o.name}: {text}"
        if text and line not in self.not_modelled:
            self.not_modelled.append(line)

    def _thickness(self, o):
        if o.obj_type.upper() in ("MATERIAL", "MATERIAL:ROOFVEGETATION"):
            return self.r.number(o, "thickness", low=0, low_open=True)
        return MASSLESS_THICKNESS

    def _faces(self, o):
        """Emissivity, solar absorptance and DOE-2 roughness multiplier of a layer's face (EnergyPlus's
        defaults where a field is blank; an air gap is no face EnergyPlus would put outermost)."""
        if o.obj_type.upper() == "MATERIAL:AIRGAP":
            return {"emissivity": 0.9, "solar": 0.7, "roughness": convection.ROUGHNESS["mediumrough"]}
        if o.obj_type.upper() == "MATERIAL:INFRAREDTRANSPARENT":
            return dict(IR_TRANSPARENT_FACE, roughness=convection.ROUGHNESS["mediumrough"])
        roughness = self.r.text(o, "roughness", "MediumRough").lower()
        if roughness not in convection.ROUGHNESS:
            self.r.fail(o, "Roughness", f"{roughness!r} is none of EnergyPlus's roughnesses")
        return {"emissivity": self.r.number(o, "thermal_absorptance", default=0.9, low=0, low_open=True, high=1),
                "solar": self.r.number(o, "solar_absorptance", default=0.7, low=0, high=1),
                "roughness": convection.ROUGHNESS[roughness]}

    def opaque_material(self, o):
        name = o.name
        if name in self.materials:
            return name
        kind = o.obj_type.upper()
        if kind == "MATERIAL":
            self.materials[name] = {"conductivity": self.r.number(o, "conductivity", low=0, low_open=True),
                                    "density": self.r.number(o, "density", low=0, low_open=True),
                                    "specific_heat": self.r.number(o, "specific_heat", low=100)}
        elif kind == "MATERIAL:ROOFVEGETATION":
            self.materials[name] = {"conductivity": self.r.number(o, "conductivity_of_dry_soil", default=0.35, low=0,
                                                                  low_open=True),
                                    "density": self.r.number(o, "density_of_dry_soil", default=1100.0, low=0,
                                                             low_open=True),
                                    "specific_heat": self.r.number(o, "specific_heat_of_dry_soil", default=1200.0,
                                                                   low=100)}
        else:
            R = IR_TRANSPARENT_RESISTANCE if kind == "MATERIAL:INFRAREDTRANSPARENT" else \
                self.r.number(o, "thermal_resistance", low=0, low_open=True)
            self.materials[name] = {"conductivity": MASSLESS_THICKNESS / R, "density": 0.0, "specific_heat": 0.0}
        return name

    def glazing_layers(self, c, objs, height):
        """A window construction: its panes and gaps as layers, U's parts, its solar transmittance
        at normal incidence, its angular table (layered glazing) and its outer face's absorptance."""
        kinds = [o.obj_type.upper() for o in objs]
        if "WINDOWMATERIAL:SIMPLEGLAZINGSYSTEM" in kinds:
            if len(objs) != 1:
                self.r.fail(c, "Outside Layer", "a simple glazing system is a construction's only layer")
            o = objs[0]
            U = self.r.number(o, "u_factor", low=0, low_open=True, high=7)
            shgc = self.r.number(o, "solar_heat_gain_coefficient", low=0, low_open=True, high=1)
            h_in, h_out = glazing.simple_glazing_films(U)
            R = 1 / U - 1 / h_in - 1 / h_out
            if R <= 0:
                self.r.fail(o, "U-Factor", f"{U:g} W/m2/K leaves no resistance for the glazing beside its films")
            name = f"{o.name} (U {U:g})"
            self.materials[name] = {"conductivity": 0.003 / R, **WINDOW_LAYER_CAPACITY}
            tau = glazing.simple_glazing_transmittance(U, shgc)
            # EnergyPlus's absorptance of the layer, half at each of its faces, as its window heat
            # balance splits a glass layer's short-wave (Engineering Reference, "Window Heat Balance
            # Calculation"); at its simple glazing model's summer films the part flowing in is then
            # SHGC - T. Split to give SHGC - T at the converter's films instead, the 2019
            # prototypes' windows let 0.004 of their sun less in, and the medium office ran 0.3 K cool
            alpha = glazing.simple_glazing_absorptance(U, shgc)
            inner = alpha / 2
            faces = {"emissivity": 0.84, "solar": alpha - inner, "roughness": 1.0}
            factors = [float(glazing.simple_glazing_factors(U, shgc, a)) for a in glazing.ANGLES]
            diffuse = glazing.hemispherical(lambda a: glazing.simple_glazing_factors(U, shgc, a))
            # its one layer absorbs the direct sun at its angle and the diffuse at its hemispherical
            # absorptance, as EnergyPlus has it, whichever face the converter puts it at
            at_angles = [round(float(glazing.simple_glazing_angular_absorptance(U, shgc, a)) / alpha, 6)
                         for a in glazing.ANGLES]
            spread = round(glazing.hemispherical(lambda a: glazing.simple_glazing_angular_absorptance(U, shgc, a))
                           / alpha, 6)
            absorptance = {"angles": list(glazing.ANGLES), "outside": at_angles, "outside_diffuse": spread,
                           "inside": at_angles, "inside_diffuse": spread}
            # the one layer absorbs alike from either side
            return [[name, 0.003]], faces, {"emissivity": 0.84, "solar": tau + alpha}, {
                "tau": tau, "inner_alpha": inner, "back_alpha": alpha, "absorptance": absorptance,
                "angular": {"angles": list(glazing.ANGLES), "factors": factors, "diffuse": diffuse}}
        panes, layers, gases = [], [], {}
        for k, o in enumerate(objs):
            kind = o.obj_type.upper()
            expected = PANES if k % 2 == 0 else ("WINDOWMATERIAL:GAS", "WINDOWMATERIAL:GASMIXTURE")
            if kind not in expected:
                self.r.fail(c, f"Layer {k + 1}", f"{o.name!r}: panes and gas gaps must alternate, a pane outermost "
                                                 "and innermost")
            if kind == "WINDOWMATERIAL:GLAZING:REFRACTIONEXTINCTIONMETHOD":
                T0, Rf = glazing.pane_from_refraction(
                    self.r.number(o, "thickness", low=0, low_open=True),
                    self.r.number(o, "solar_index_of_refraction", low=1, low_open=True),
                    self.r.number(o, "solar_extinction_coefficient", low=0, low_open=True))
                emissivity = self.r.number(o, "infrared_hemispherical_emissivity", default=0.84, low=0, low_open=True,
                                           high=1)
                panes.append((T0, Rf, emissivity, emissivity))
            elif kind == "WINDOWMATERIAL:GLAZING":
                optical = self.r.text(o, "optical_data_type", "SpectralAverage").lower()
                if optical == "spectral":
                    T0, Rf = self.spectral_pane(o)
                elif optical == "spectralaverage":
                    T0 = self.r.number(o, "solar_transmittance_at_normal_incidence", low=0, low_open=True, high=1)
                    Rf = self.r.number(o, "front_side_solar_reflectance_at_normal_incidence", low=0, high=1)
                else:
                    self.r.fail(o, "Optical Data Type", f"{optical!r}: SpectralAverage and Spectral pane data are read "
                                                        "(a BSDF pane is not)")
                panes.append((T0, Rf, self.r.number(o, "front_side_infrared_hemispherical_emissivity", default=0.84),
                              self.r.number(o, "back_side_infrared_hemispherical_emissivity", default=0.84)))
            if kind in PANES:
                thickness = self.r.number(o, "thickness", low=0, low_open=True)
                name = o.name
                self.materials.setdefault(name, {"conductivity": self.r.number(o, "conductivity", low=0, low_open=True),
                                                 **WINDOW_LAYER_CAPACITY})
                layers.append([name, thickness])
            else:
                layers.append([o.name, self.r.number(o, "thickness", low=0, low_open=True)])
                gases[k] = self.gas(o)
        return self._stack(c.name, panes, layers, gases, height)

    def _stack(self, construction, panes, layers, gases, height):
        """A layered glazing's layers, faces and optics from its panes (T0, Rf, front and back
        emissivity), its layers ([name, thickness], panes and gaps alternating) and each gap's gas."""
        # a gap's conductance depends on the emissivities facing it and the pane's height
        for k in range(1, len(layers), 2):
            gap, d = layers[k]
            h = glazing.gap_conductance(d, height or 1.5, panes[k // 2][3], panes[k // 2 + 1][2], gas=gases[k])
            name = f"{gap} in {construction}"
            self.materials[name] = {"conductivity": h * d, **WINDOW_LAYER_CAPACITY}
            layers[k] = [name, d]
        pairs = [(T0, R0) for T0, R0, _, _ in panes]
        tau = float(glazing.stack_transmittance(pairs, 0.0))
        factors = [float(glazing.stack_transmittance(pairs, a)) / tau for a in glazing.ANGLES]
        diffuse = glazing.hemispherical(lambda a: glazing.stack_transmittance(pairs, a)) / tau
        alpha, inner_alpha = _sides(glazing.pane_absorptances(pairs))
        # as EnergyPlus absorbs the direct sun in each pane at its angle and the diffuse at the
        # panes' hemispherical absorptance
        def sides_at(angles):
            """(2, len(angles)): the outer and the inner panes' absorptance of the direct sun."""
            return np.array([_sides(row) for row in glazing.angular_pane_absorptances(pairs, angles)]).T

        at_angles, hemispherical = sides_at(glazing.ANGLES).T, glazing.hemispherical(sides_at)
        absorptance = {"angles": list(glazing.ANGLES)}
        for k, side in enumerate(("outside", "inside")):
            normal = (alpha, inner_alpha)[k]
            absorptance[side] = [round(float(f) / normal, 6) if normal > 0 else 1.0 for f in at_angles[:, k]]
            absorptance[f"{side}_diffuse"] = round(hemispherical[k] / normal, 6) if normal > 0 else 1.0
        # seen from the room, a glazing takes the diffuse sun it does not reflect (out, or into its panes)
        outer = {"emissivity": panes[0][2], "solar": alpha, "roughness": 1.0}  # glass is very smooth
        inner = {"emissivity": panes[-1][3], "solar": 1 - glazing.stack_reflectance(pairs[::-1])}
        # each gap between the outer pane's back and the inner pane's front, from the inside face as
        # the building file counts its layers, its conductance following the panes' (docs/model.md 4.1)
        gaps = [{"layer": len(layers) - 1 - k, "emissivities": [panes[k // 2 + 1][2], panes[k // 2][3]],
                 "gas": _json_gas(gases[k])} for k in range(1, len(layers), 2)]
        return layers, outer, inner, {"tau": tau, "inner_alpha": inner_alpha, "gaps": gaps, "absorptance": absorptance,
                                      "back_alpha": sum(glazing.pane_absorptances(pairs[::-1])),
                                      "angular": {"angles": list(glazing.ANGLES), "factors": factors,
                                                  "diffuse": diffuse}}

    def window_data_file(self, c, height):
        """A Construction:WindowDataFile as EnergyPlus builds it: the panes and gaps of the window
        of the construction's name in the WINDOW data file (its first glazing system), each pane's
        spectral averages, each gap's gases at the file's own coefficients (`read_window5`)."""
        written = self.r.text(c, "file_name") or "Window5DataFile.dat"
        folder = Path(self.r.source).resolve().parent
        relative = Path(written.replace("\\", "/"))
        found = next((p for p in (folder / relative, folder / relative.name) if p.is_file()), None)
        if found is None:
            self.r.fail(c, "File Name", f"{written!r} is not found beside the IDF (EnergyPlus stops without it too)")
        try:
            window = read_window5(found.read_text(encoding="latin-1"), c.name)
        except ValueError as e:
            self.r.fail(c, "File Name", f"{written!r}: {e}")
        panes, layers, gases = [], [], {}
        for k, pane in enumerate(window["panes"]):
            name = f"{c.name} pane {k + 1}"
            self.materials[name] = {"conductivity": pane["conductivity"], **WINDOW_LAYER_CAPACITY}
            panes.append((pane["T"], pane["R_front"], pane["emissivity_front"], pane["emissivity_back"]))
            layers.append([name, pane["thickness"]])
            if k < len(window["gaps"]):
                gap = window["gaps"][k]
                layers.append([f"{c.name} gap {k + 1}", gap["thickness"]])
                gases[len(layers) - 1] = gap["gas"]
        line = (f"Construction:WindowDataFile {c.name}: its panes and gaps read from {found.name}; the file's "
                "angle-dependent optical table, frame and divider not held (the panes' own angular behaviour used)")
        if line not in self.not_modelled:
            self.not_modelled.append(line)
        return self._stack(c.name, panes, layers, gases, height)

    def spectral_pane(self, o):
        """(T, R_front) at normal incidence of a pane given by wavelength
        (MaterialProperty:GlazingSpectralData): each averaged over the solar spectrum EnergyPlus
        weighs with (`model.glazing.solar_average`)."""
        data = self.r.get("MaterialProperty:GlazingSpectralData", self.r.text(o, "window_glass_spectral_data_set_name"),
                          o, "Window Glass Spectral Data Set Name")
        fields = data.to_dict()
        rows = fields.get("extensions") or []
        k = 1
        while f"wavelength_{k}" in fields:  # the fields as numbered in the IDD
            rows.append({f: fields.get(f"{f}_{k}") for f in ("wavelength", "transmittance", "front_reflectance")})
            k += 1
        if len(rows) < 2:
            self.r.fail(data, "Wavelength 1", "a spectrum needs at least two wavelengths")
        try:
            table = np.array([[float(r["wavelength"]), float(r["transmittance"]), float(r["front_reflectance"])]
                              for r in rows])
        except (KeyError, TypeError, ValueError):
            self.r.fail(data, "Wavelength 1", "a wavelength, transmittance or reflectance is not a number")
        self.note("a pane's spectral data averaged over EnergyPlus's solar spectrum pane by pane (EnergyPlus "
                  "integrates the whole glazing wavelength by wavelength)")
        return (glazing.solar_average(table[:, 0], table[:, 1]), glazing.solar_average(table[:, 0], table[:, 2]))

    def gas(self, o):
        """A gap's gas as `model.glazing.gas_properties` reads it: a name, a Custom gas's own
        coefficients, or a WindowMaterial:GasMixture's gases and fractions."""
        if o.obj_type.upper() == "WINDOWMATERIAL:GASMIXTURE":
            n = int(self.r.number(o, "number_of_gases_in_mixture", low=1, high=4))
            mixture = []
            for i in range(1, n + 1):
                name = self.r.text(o, f"gas_{i}_type").lower()
                if name not in glazing.GASES:
                    self.r.fail(o, f"Gas {i} Type", f"{name!r} is none of {', '.join(glazing.GASES)}")
                mixture.append((name, self.r.number(o, f"gas_{i}_fraction", low=0, low_open=True, high=1)))
            self.note("a gas mixture's properties the mole-fraction-weighted means of its gases' (EnergyPlus mixes "
                      "by ISO 15099's rules)")
            return mixture
        name = self.r.text(o, "gas_type", "Air").lower()
        if name == "custom":
            coefficients = [tuple(self.r.number(o, f"{p}_coefficient_{c}", default=0.0) for c in "abc")
                            for p in ("conductivity", "viscosity", "specific_heat")]
            return (*coefficients, self.r.number(o, "molecular_weight", low=0, low_open=True))
        if name not in glazing.GASES:
            self.r.fail(o, "Gas Type", f"{name!r} is none of Air, Argon, Krypton, Xenon, Custom")
        return name

    # ---- zones, surfaces ----------------------------------------------------------------
    def building(self):
        site = self.site()
        self.geometry_rules()
        steps = self.r.all("Timestep")
        self.timesteps = int(self.r.number(steps[0], "number_of_timesteps_per_hour", default=6)) if steps else 6
        zones = self.r.all("Zone")
        if not zones:
            self.r.fail(None, "Zone", "missing: the model has no zone")
        self.zone_objs = {z.name.upper(): z for z in zones}
        surfaces = self.surfaces_by_name = self.surfaces()
        zone_data = [self.zone(z, surfaces) for z in zones]
        self.air_boundaries(surfaces, zone_data)
        components = self.components(surfaces)
        self.user_view_factors(zone_data, components, surfaces)
        shading = self.shading(components, surfaces)
        for z in zone_data:
            z.pop("_floor_area")
        self.internal_masses(components)
        self.receivers(components)
        self.list_not_modelled()
        names = [b.name for b in self.r.all("Building")]
        description = (f"Converted by nodeforce convert from {self.r.source} (EnergyPlus "
                       f"{'.'.join(map(str, self.r.doc.version[:2]))}). Inside convection by each zone's algorithm, TARP "
                       "from each step's face-to-air differences (its value at a "
                       f"{FILMS.delta_T:g} K difference in the step matrix), Simple constant "
                       "(docs/guide.md, nodeforce convert); " + "; ".join(self.notes or ["no other assumption"]) + ".")
        data = {"format": "nodal-building/1", "name": names[0] if names else "", "description": description,
                "site": site, "materials": self.materials, "zones": zone_data, "components": components}
        built = {c["name"] for c in components}
        constructions = {name: [c for c in names if c in built] for name, names in self.constructions.values()}
        if any(constructions.values()):
            data["constructions"] = {name: names for name, names in constructions.items() if names}
        if shading:
            data["shading"] = shading
        if self.schedules:
            data["schedules"] = self.schedules
        data["not_modelled"] = self.not_modelled
        data["energyplus"] = {"idf": self.r.source}
        return data

    def zone_transform(self, zone):
        """(origin m, rotation deg) that bring a zone's vertices to true-north coordinates."""
        if not self.relative:
            return np.zeros(3), self.north
        origin = np.array([self.r.number(zone, f, default=0.0) for f in ("x_origin", "y_origin", "z_origin")])
        return origin, self.north + self.r.number(zone, "direction_of_relative_north", default=0.0)

    def surfaces(self):
        """{upper name: dict} of every heat transfer surface: zone, kind, boundary, vertices (true
        north, m) or area and orientation, construction, exposure."""
        out = {}
        for kind in SURFACES:
            for s in self.r.all(kind):
                zone = self.zone_of(s, "zone_name")
                vertices = self.vertices(s, zone)
                out[s.name.upper()] = dict(obj=s, zone=zone.name, type=self.r.text(s, "surface_type", kind.split(":")[0]),
                                           boundary=self.r.text(s, "outside_boundary_condition"),
                                           other=self.r.text(s, "outside_boundary_condition_object"),
                                           sun=self.r.text(s, "sun_exposure", "SunExposed").lower() == "sunexposed",
                                           wind=self.r.text(s, "wind_exposure", "WindExposed").lower() == "windexposed",
                                           construction=self.r.text(s, "construction_name"), vertices=vertices,
                                           space=self.r.text(s, "space_name"))
        for kind, (stype, boundary) in SIMPLE_SURFACES.items():
            for s in self.r.all(kind):
                zone = self.zone_of(s, "zone_name")
                _, turn = self.zone_transform(zone) if self.rect_relative else (None, self.north)
                length = self.r.number(s, "length", low=0, low_open=True)
                other = self.r.number(s, "height" if stype == "Wall" else "width", low=0, low_open=True)
                tilt = self.r.number(s, "tilt_angle", default={"Wall": 90, "Roof": 0, "Ceiling": 0, "Floor": 180}[stype])
                azimuth = (self.r.number(s, "azimuth_angle", default=0.0) + turn) % 360
                out[s.name.upper()] = dict(obj=s, zone=zone.name, type=stype,
                                           boundary=boundary if boundary != "Interzone" else "Surface",
                                           other=self.r.text(s, "outside_boundary_condition_object"),
                                           sun=boundary == "Outdoors", wind=boundary == "Outdoors",
                                           construction=self.r.text(s, "construction_name"), vertices=None,
                                           space=self.r.text(s, "space_name"), area=length * other, azimuth=azimuth,
                                           tilt=tilt,
                                           height=self._rect_height(s, zone, stype, other, tilt))
                z0 = out[s.name.upper()]["height"] - 0.5 * other * np.sin(np.radians(tilt))
                out[s.name.upper()]["z_range"] = tuple(sorted((z0, z0 + other * np.sin(np.radians(tilt)))))
        if not out:
            self.r.fail(None, "BuildingSurface:Detailed", "missing: the model has no heat transfer surface")
        for s in out.values():
            if s["vertices"] is not None:
                normal = geometry.outward_normal(s["vertices"], self.ccw)
                s["azimuth"], s["tilt"] = geometry.azimuth_tilt(normal)
                s["area"] = geometry.area(s["vertices"])
                s["height"] = float(np.mean(s["vertices"][:, 2]))
                s["z_range"] = (float(s["vertices"][:, 2].min()), float(s["vertices"][:, 2].max()))
            s["subsurfaces"] = []
        for kind in SUBSURFACES:
            for w in self.r.all(kind):
                parent_name = self.r.text(w, "building_surface_name")
                parent = out.get(parent_name.upper())
                if parent is None:
                    self.r.fail(w, "Building Surface Name", f"names no heat transfer surface ({parent_name!r})")
                multiplier = self.r.number(w, "multiplier", default=1.0, low=1)
                vertices = None
                if kind == "FenestrationSurface:Detailed":
                    vertices = self.vertices(w, self.zone_objs[parent["zone"].upper()])
                    area = geometry.area(vertices) * multiplier
                    stype = self.r.text(w, "surface_type", "Window")
                    height = np.ptp(vertices[:, 2]) or None
                else:
                    length = self.r.number(w, "length", low=0, low_open=True)
                    height = self.r.number(w, "height", low=0, low_open=True)
                    area = length * height * multiplier
                    stype = kind.split(":")[0]
                    if parent["vertices"] is not None:  # where a shade's shadow falls on it
                        base = parent["vertices"] if self.ccw else parent["vertices"][::-1]
                        vertices = on_surface(base, parent["azimuth"], parent["tilt"],
                                              self.r.number(w, "starting_x_coordinate", default=0.0),
                                              self.r.number(w, "starting_z_coordinate", default=0.0), length, height)
                        vertices = vertices if self.ccw else vertices[::-1]
                parent["subsurfaces"].append(dict(obj=w, type=stype, area=area, height=height, vertices=vertices,
                                                  construction=self.r.text(w, "construction_name"),
                                                  other=self.r.text(w, "outside_boundary_condition_object")))
        return out

    def _rect_height(self, s, zone, stype, other, tilt):
        """Centroid height (m) of a rectangular surface: its starting corner's z plus half its rise."""
        z0 = self.r.number(s, "starting_z_coordinate", default=0.0)
        if self.rect_relative:
            z0 += self.r.number(zone, "z_origin", default=0.0)
        return z0 + 0.5 * other * np.sin(np.radians(tilt))

    def zone_of(self, obj, field):
        name = self.r.text(obj, field)
        zone = self.zone_objs.get(name.upper())
        if zone is None:
            self.r.fail(obj, _field_label(obj, field), f"names no Zone ({name!r})")
        return zone

    def vertices(self, s, zone):
        """A surface's vertices (n, 3) in true-north coordinates, m, as its zone places them."""
        origin, turn = self.zone_transform(zone)
        return geometry.rotate_z(self.points(s) + origin, turn)

    def points(self, s):
        """A surface's vertices (n, 3) as the object writes them, m, checked to be numbers and a
        plane polygon."""
        fields = s.to_dict()
        if isinstance(fields.get("vertices"), list):
            v = [[p["vertex_x_coordinate"], p["vertex_y_coordinate"], p["vertex_z_coordinate"]] for p in fields["vertices"]]
        else:
            v, k = [], 1
            while f"vertex_{k}_x_coordinate" in fields and not _blank(fields[f"vertex_{k}_x_coordinate"]):
                v.append([fields[f"vertex_{k}_{a}_coordinate"] for a in "xyz"])
                k += 1
        for k, point in enumerate(v):
            for axis, value in zip("XYZ", point):
                try:
                    float(value)
                except (TypeError, ValueError):
                    field = f"Vertex {k + 1} {axis}-coordinate"
                    if str(value).strip().startswith("="):
                        self.r.fail(s, field, f"{value!r} is a parametric expression: expand the file with "
                                              "EnergyPlus's ParametricPreprocessor first, as EnergyPlus itself needs")
                    self.r.fail(s, field, f"{value!r} is not a number")
        v = np.array(v, dtype=float)
        if len(v) < 3:
            self.r.fail(s, "Number of Vertices", f"{len(v)} vertices: a surface needs at least 3")
        if geometry.area(v) <= 1e-9:
            self.r.fail(s, "Vertex 1 X-coordinate", "the vertices enclose no area")
        self.check_planar(s, v)
        return v

    def zone_volume(self, z, own, floor):
        """An autocalculated zone volume (m3), as EnergyPlus's CalculateZoneVolume: a zone its
        surfaces close (their area-weighted outward normals sum to nothing) by the divergence
        theorem, sum over faces of A (x . n) / 3; any other its floor area times its ceiling height
        (the field's, else the height its surfaces span), exact for a prism."""
        polygons = [s["vertices"] for s in own if s["vertices"] is not None]
        if len(polygons) == len(own) and geometry_closed(polygons, self.ccw):
            volume = geometry.enclosed_volume(polygons, self.ccw)
            if volume > 0:
                return volume
        height = _field(z, "ceiling_height")
        if _autocalculated(height):
            height = max(s["z_range"][1] for s in own) - min(s["z_range"][0] for s in own)
        else:
            height = self.r.number(z, "ceiling_height", low=0, low_open=True)
        if floor * height <= 0:
            self.r.fail(z, "Volume", "autocalculated for a zone whose surfaces enclose no volume and that has no floor "
                                     "area or height: give the volume")
        self.note("a zone whose surfaces do not close it takes its floor area times its height as volume, as "
                  "EnergyPlus does")
        return floor * height

    def check_planar(self, s, v):
        """A polygon's vertices off its plane (Newell's normal through their centroid): beyond
        PLANAR_LISTED listed (its area and orientation are its plane's), beyond PLANAR_REFUSED of
        its size refused (no plane stands for it)."""
        n = geometry.outward_normal(v)
        off = np.abs((v - v.mean(axis=0)) @ n)
        k = int(np.argmax(off))
        if off[k] > PLANAR_REFUSED * np.sqrt(geometry.area(v)):
            self.r.fail(s, f"Vertex {k + 1} X-coordinate", f"{off[k]:.3f} m off the surface's plane: not a planar "
                                                           "surface")
        if off[k] > PLANAR_LISTED:
            self.approximated({"obj": s}, f"not planar (vertex {k + 1} {off[k]:.3f} m off its plane): its area and "
                                          "orientation those of its best plane")

    def zone(self, z, surfaces):
        own = [s for s in surfaces.values() if s["zone"].upper() == z.name.upper()]
        if not own:
            self.r.fail(z, "Name", "no surface belongs to this zone")
        multiplier = self.r.number(z, "multiplier", default=1.0, low=1)
        if multiplier != 1:
            # its copies are identical zones: free-floating, each has the one zone's temperature;
            # what a copy exchanges with another zone is counted once
            self.not_modelled.append(f"Zone {z.name}: multiplier {multiplier:g} not held; the zone is modelled once "
                                     "(each copy's air as its own; its partitions with other zones counted once)")
        # faces of other zones' surfaces whose outside names this zone (a plenum's floor is often only
        # the ceilings below naming it): part of its enclosure, seen from it reversed
        beyond = [dict(s, vertices=None if s["vertices"] is None else s["vertices"][::-1],
                       type={"ceiling": "floor", "floor": "ceiling", "roof": "floor"}.get(s["type"].lower(), s["type"]))
                  for s in surfaces.values() if s["zone"].upper() != z.name.upper()
                  and s["boundary"].lower() in ("zone", "surface") and s["other"].upper() == z.name.upper()]
        floor = sum(s["area"] for s in own + beyond if s["type"].lower() == "floor")
        if not _autocalculated(_field(z, "floor_area")):
            floor = self.r.number(z, "floor_area", low=0, low_open=True)
        if _autocalculated(_field(z, "volume")):
            volume = self.zone_volume(z, own + beyond, floor)
        else:
            volume = self.r.number(z, "volume", low=0, low_open=True)
        data = {"name": z.name, "volume": round(volume, 6), "_floor_area": floor}
        if self.inside_algorithm(z.name) == "tarp":
            # each face's coefficient at its own difference from the air, as EnergyPlus's TARP, and
            # a layered window's inside face by ISO 15099 (its `window`)
            data["inside_convection_algorithm"] = "tarp"
        exterior = sum(s["area"] for s in own if s["boundary"].lower() == "outdoors")
        walls = sum(s["area"] for s in own if s["boundary"].lower() == "outdoors" and s["type"].lower() == "wall")
        heights = [s["height"] for s in own if s.get("height") is not None]
        flow, scheduled = self.air_flows(z, volume, floor, exterior, walls,
                                         float(np.mean(heights)) if heights else FLOW_WIND_HEIGHT)
        if flow:
            data["air_change_rate"] = flow / volume
        if scheduled:
            data["ventilation"] = scheduled
        gains = self.gains(z, floor)
        if gains:
            data["gains"] = gains
        return data

    def _targets(self, obj, field):
        """The zones an object's Zone or ZoneList name field names."""
        return [zone for zone, _ in self._places(obj, field)]

    def _places(self, obj, field):
        """[(zone name, Space name or None)] of what an object's Zone, ZoneList, Space or SpaceList
        name field names: a Space acts on its zone."""
        name = self.r.text(obj, field)
        if name.upper() in self.zone_objs:
            return [(self.zone_objs[name.upper()].name, None)]
        if name.upper() in self.r.by_name.get("SPACE", {}):
            return [self._space_place(name, obj, field)]
        for kind in ("ZONELIST", "SPACELIST"):
            members = self.r.by_name.get(kind, {}).get(name.upper())
            if members is None:
                continue
            fields = members.to_dict()
            listed = next((v for v in fields.values() if isinstance(v, list)), None)  # its extensible group
            names = ([next(iter(d.values())) for d in listed] if listed is not None
                     else [v for k, v in fields.items() if k != "name" and not _blank(v)])
            if kind == "ZONELIST":
                return [(n, None) for n in names]
            return [self._space_place(n, members, "Space Name") for n in names]
        self.r.fail(obj, _field_label(obj, field), f"names no Zone, ZoneList, Space or SpaceList ({name!r})")

    def _space_place(self, name, referrer, field):
        space = self.r.get("Space", name, referrer, field)
        return self.zone_of(space, "zone_name").name, space.name

    def _in_space(self, s, space):
        """Whether a surface is in a Space: it names it, or names none in a zone of that one Space
        (EnergyPlus puts it in the zone's only space)."""
        named = s.get("space", "")
        if named:
            return named.upper() == space.upper()
        return [o.name.upper() for o in self.r.all("Space")
                if self.r.text(o, "zone_name").upper() == s["zone"].upper()] == [space.upper()]

    def place_measures(self, z, space, measures):
        """(floor m2, volume m3, exterior m2, exterior walls m2) over which a per-area method acts in
        zone z: the zone's `measures`, or its Space's: the Space's floor area field, else its floor
        surfaces', its exterior surfaces', its Volume field, else the zone's volume in proportion to
        floor area."""
        if space is None:
            return measures
        floor, volume = measures[:2]
        own = [s for s in self.surfaces_by_name.values()
               if s["zone"].upper() == z.name.upper() and self._in_space(s, space)]
        obj = self.r.get("Space", space, None, "Space")
        area = sum(s["area"] for s in own if s["type"].lower() == "floor")
        if not _autocalculated(_field(obj, "floor_area")):
            area = self.r.number(obj, "floor_area", low=0)
        share = volume * area / floor if floor > 0 else 0.0
        if not _autocalculated(_field(obj, "volume")):
            share = self.r.number(obj, "volume", low=0)
        outdoor = [s for s in own if s["boundary"].lower() == "outdoors"]
        return (area, share, sum(s["area"] for s in outdoor),
                sum(s["area"] for s in outdoor if s["type"].lower() == "wall"))

    def _acting(self, obj, z, measures, field="zone_or_zonelist_name"):
        """The measures (`place_measures`) of each place in zone z that an object acts on."""
        return [self.place_measures(z, space, measures) for zone, space in self._places(obj, field)
                if zone.upper() == z.name.upper()]

    def air_flows(self, z, volume, floor, exterior, walls, wind_height=FLOW_WIND_HEIGHT):
        """The zone's constant outdoor air flow (m3/h) from its design flow rate objects, and its
        scheduled ones and those that follow the temperatures, the wind or controls (the building
        file's `ventilation`), the wind taken to the zone's height `wind_height` (m)."""
        total, scheduled = 0.0, []
        for kind in FLOWS:
            for o in self.r.all(kind):
                places = self._acting(o, z, (floor, volume, exterior, walls))
                if not places:
                    continue
                method = self.r.text(o, "design_flow_rate_calculation_method", "Flow/Zone").lower()
                per = {"flow/zone": ("design_flow_rate", lambda m: 3600.0),
                       "flow/area": ("flow_per_zone_floor_area" if kind == FLOWS[0] else "flow_rate_per_zone_floor_area",
                                     lambda m: 3600.0 * m[0]),
                       "flow/exteriorarea": ("flow_per_exterior_surface_area", lambda m: 3600.0 * m[2]),
                       "flow/exteriorwallarea": ("flow_per_exterior_surface_area", lambda m: 3600.0 * m[3]),
                       "airchanges/hour": ("air_changes_per_hour", lambda m: m[1]),
                       "flow/person": ("flow_rate_per_person", None)}
                if method not in per or per[method][1] is None:
                    self.r.fail(o, "Design Flow Rate Calculation Method", f"{method!r} is not read (Flow/Zone, Flow/Area, "
                                "Flow/ExteriorArea, Flow/ExteriorWallArea, AirChanges/Hour are)")
                field, scale = per[method]
                flow = self.design_value(o, field) * sum(scale(m) for m in places)
                # EnergyPlus's flow is the design flow times max(0, A + B |dT| + C v + D v^2), v the
                # wind at the zone's height: the building file's `terms`, followed step by step
                terms = [self.r.number(o, "constant_term_coefficient", default=1.0)] + [
                    self.r.number(o, f, default=0.0) for f in ("temperature_term_coefficient",
                                                               "velocity_term_coefficient",
                                                               "velocity_squared_term_coefficient")]
                entry = {"name": o.name, **(self.ventilation_controls(o) if kind == FLOWS[1] else {})}
                if any(terms[1:]) or "controls" in entry and terms[0] != 1.0:
                    entry["terms"] = terms
                if "terms" not in entry and "controls" not in entry:
                    flow *= terms[0]
                if "terms" in entry and (terms[2] or terms[3]) or "maximum_wind_speed" in entry.get("controls", {}):
                    entry["wind_factor"] = round(float(convection.wind_at_height(1.0, wind_height, self.terrain)), 6)
                name = self.r.text(o, "schedule_name")
                value = self.constant_schedule_value(name, o, "Schedule Name") if name else 1.0
                if value is None:
                    if np.min([v for p in self.schedules[name]["days"].values() for _, v in p]) < 0:
                        self.r.fail(o, "Schedule Name", f"{name!r} takes negative values: an air flow is >= 0")
                    entry.update(flow=flow, schedule=name)
                else:
                    entry["flow"] = flow * value
                if entry["flow"] <= 0:
                    continue
                if len(entry) > 2:
                    scheduled.append(entry)
                else:
                    total += entry["flow"]
        return total, scheduled

    def ventilation_controls(self, o):
        """{"controls": {...}} of a ZoneVentilation:DesignFlowRate's limits that it declares (the
        building file's ventilation controls; their schedules, where declared, are not held)."""
        controls, scheduled = {}, []
        for field, schedule in (("minimum_indoor_temperature", "minimum_indoor_temperature_schedule_name"),
                                ("maximum_indoor_temperature", "maximum_indoor_temperature_schedule_name"),
                                ("delta_temperature", "delta_temperature_schedule_name"),
                                ("minimum_outdoor_temperature", "minimum_outdoor_temperature_schedule_name"),
                                ("maximum_outdoor_temperature", "maximum_outdoor_temperature_schedule_name"),
                                ("maximum_wind_speed", None)):
            if not _blank(_field(o, field)):
                controls[field] = self.r.number(o, field)
            if schedule is not None and not _blank(_field(o, schedule)):
                scheduled.append(_field_label(o, schedule))
        if scheduled:
            self.not_modelled.append(f"ZoneVentilation:DesignFlowRate {o.name}: its control schedules "
                                     f"({', '.join(scheduled)}) not held; its constant limits are")
        return {"controls": controls} if controls else {}

    def gains(self, z, floor):
        out = []
        for kind in GAINS:
            for o in self.r.all(kind):
                floors = [m[0] for m in self._acting(o, z, (floor, 0.0, 0.0, 0.0))]
                if not floors:
                    continue
                if kind == "People":
                    out.append(self.people(o, floors))
                    continue
                method_field, fields = "design_level_calculation_method", GAIN_FIELDS[kind]
                method = self.r.text(o, method_field).lower()
                if method not in fields:
                    self.r.fail(o, _label(method_field), f"{method!r} is not read ({', '.join(fields)} are)")
                # each place (a zone, or a space) of the object's list gets the whole level
                spaces = [space for zone, space in self._places(o, "zone_or_zonelist_name")
                          if zone.upper() == z.name.upper()]
                per = {"watts/area": sum(floors),
                       "watts/person": sum(self.zone_people(z, floor, space) for space in spaces)}.get(method, len(floors))
                power = self.design_value(o, fields[method]) * per
                if kind == "Lights":
                    radiant = self.r.number(o, "fraction_radiant", default=0.0) + self.r.number(o, "fraction_visible", default=0.0)
                    returned = self.r.number(o, "return_air_fraction", default=0.0)
                    if returned:
                        # EnergyPlus puts it in the return air; without an air system (free-floating) no
                        # zone gets it: 28.4 C in the 2004 medium office's mid core, 30.1 C given to the zone
                        self.not_modelled.append(f"Lights {o.name}: return air fraction {returned:g} leaves with the "
                                                 "return air, as in EnergyPlus without an air system (no zone gets it)")
                    sensible = 1.0 - returned
                else:
                    radiant = self.r.number(o, "fraction_radiant", default=0.0)
                    sensible = 1.0 - self.r.number(o, "fraction_latent", default=0.0) - self.r.number(o, "fraction_lost", default=0.0)
                if sensible <= 0:
                    out.append(None)
                    continue
                gain = {"name": o.name, "power": power * sensible, "radiant_fraction": min(1.0, radiant / sensible)}
                self._gain_schedule(gain, o)
                out.append(gain)
        return [g for g in out if g is not None]

    def _gain_schedule(self, gain, o, field="schedule_name"):
        name = self.r.text(o, field)
        if not name:
            return
        value = self.constant_schedule_value(name, o, _label(field))
        if value is None:
            gain["schedule"] = name
        else:
            gain["power"] *= value

    def design_value(self, o, field):
        """The number a gain's or flow's calculation method reads; blank is 0, as EnergyPlus reads
        a blank number (its other methods' fields are never required). An OtherEquipment's may be
        negative: EnergyPlus's IDD has no minimum there, and a negative level removes heat."""
        if _blank(_field(o, field)):
            self.note(f"a blank design level of a {o.obj_type} read as 0, as EnergyPlus reads it")
            return 0.0
        return self.r.number(o, field, low=None if o.obj_type.lower() == "otherequipment" else 0)

    def people_count(self, o, floor):
        """A People object's design number of people in a zone of `floor` m2, by its own method."""
        method = self.r.text(o, "number_of_people_calculation_method", "People").lower()
        if method == "people":
            return self.design_value(o, "number_of_people")
        if method == "people/area":
            return self.design_value(o, "people_per_zone_floor_area") * floor
        if method == "area/person":
            per = self.design_value(o, "zone_floor_area_per_person")
            return floor / per if per > 0 else 0.0
        self.r.fail(o, "Number of People Calculation Method", f"{method!r} is not read")

    def zone_people(self, z, floor, space=None):
        """The design number of people of a zone, the sum of its People objects' (EnergyPlus's
        TotOccupants, on which a Watts/Person gain's design level stands), or of one of its Spaces:
        the People naming it, and the zone's own People in proportion to the space's floor area."""
        share = 1.0  # the part of the zone's own People in the space
        if space is not None:
            share = self.place_measures(z, space, (floor, 0.0, 0.0, 0.0))[0] / floor if floor > 0 else 0.0
        total = 0.0
        for o in self.r.all("People"):
            for zone, where in self._places(o, "zone_or_zonelist_name"):
                if zone.upper() != z.name.upper():
                    continue
                area = self.place_measures(z, where, (floor, 0.0, 0.0, 0.0))[0]
                if space is None or where is None:
                    total += self.people_count(o, area) * (share if where is None else 1.0)
                elif where.upper() == space.upper():
                    total += self.people_count(o, area)
        return total

    def people(self, o, floors):
        n = sum(self.people_count(o, area) for area in floors)
        activity = self.constant_schedule_value(self.r.text(o, "activity_level_schedule_name"), o,
                                                "Activity Level Schedule Name")
        if activity is None:
            self.r.fail(o, "Activity Level Schedule Name", "varies in time: a gain has one schedule; give a constant activity")
        sensible = _field(o, "sensible_heat_fraction")
        gain = {"name": o.name, "radiant_fraction": self.r.number(o, "fraction_radiant", default=0.0, low=0, high=1)}
        if _blank(sensible) or str(sensible).lower() in ("autocalculate", "autosize"):
            # EnergyPlus's polynomial in the activity and the zone's air, followed at each step (it
            # is 0 above some 36 C, where its line about PEOPLE_T would take heat out of a hot
            # zone), its line about PEOPLE_T in the step matrix
            gain["power"] = float(n * people_sensible_heat(activity))
            slope = n * people_sensible_slope(activity)
            if slope < 0:
                gain.update(temperature_slope=slope, reference_temperature=PEOPLE_T)
            if n > 0:
                gain["people"] = {"number": n, "activity": activity}
        else:
            gain["power"] = n * activity * self.r.number(o, "sensible_heat_fraction", low=0, high=1)
        self._gain_schedule(gain, o, "number_of_people_schedule_name")
        return gain

    def pair_owner(self, s, surfaces):
        """Of two surfaces naming each other, the one that becomes the partition (its inside the
        first's zone): the one whose zone comes first in the file's zones, then by name, so that the
        order of the two objects does not change the building."""
        other = surfaces.get(s["other"].upper())
        if other is None or other["other"].upper() != s["obj"].name.upper() or other is s:
            return s
        order = {name: k for k, name in enumerate(self.zone_objs)}
        key = lambda t: (order[t["zone"].upper()], t["obj"].name.upper())  # noqa: E731
        return min((s, other), key=key)

    def air_boundary(self, s):
        """The Construction:AirBoundary a surface is made of, or None."""
        return self.r.by_name.get("CONSTRUCTION:AIRBOUNDARY", {}).get(s["construction"].upper())

    def air_boundaries(self, surfaces, zone_data):
        """Each pair of zones an air boundary joins exchanges air both ways, as EnergyPlus's
        SimpleMixing makes a pair of ZoneMixing objects: V = ACH x the smaller zone's volume (m3/h),
        the air of each zone entering the other (the building file's `airflow_from`). The surface
        conducts nothing; the radiant and solar exchange across the opening are not held."""
        by_zone = {z["name"].upper(): z for z in zone_data}
        done = set()
        for s in surfaces.values():
            c = self.air_boundary(s)
            if c is None:
                continue
            boundary, other_name = s["boundary"].lower(), s["other"].upper()
            other = surfaces.get(other_name)
            beyond = other["zone"] if other is not None else \
                self.zone_objs[other_name].name if other_name in self.zone_objs else None
            if boundary not in ("surface", "zone") or beyond is None:
                self.r.fail(s["obj"], "Outside Boundary Condition Object",
                            f"{c.name!r} is a Construction:AirBoundary: it needs a zone on its other side")
            if beyond.upper() == s["zone"].upper():
                continue  # between two spaces of one zone: one air, one radiant enclosure already
            pair = tuple(sorted((s["zone"].upper(), beyond.upper())))
            method = self.r.text(c, "air_exchange_method", "None").lower()
            first, second = sorted((s["zone"], beyond), key=str.upper)
            line = (f"Construction:AirBoundary {c.name} between {first} and {second}: not a conducting surface; "
                    "the radiant and solar exchange through the opening not held")
            if line not in self.not_modelled:
                self.not_modelled.append(line)
            if method != "simplemixing" or pair in done:
                continue
            done.add(pair)
            ach = self.r.number(c, "simple_mixing_air_changes_per_hour", default=0.5, low=0)
            scale = 1.0
            name = self.r.text(c, "simple_mixing_schedule_name")
            if name:
                scale = self.constant_schedule_value(name, c, "Simple Mixing Schedule Name")
                if scale is None:
                    scale = max(v for day in self.schedules[name]["days"].values() for _, v in day)
                    self.not_modelled.append(f"Construction:AirBoundary {c.name}: its schedule {name!r} varies: the "
                                             f"mixing taken at its largest value, {scale:g}, all year")
            a, b = (by_zone[z] for z in pair)
            flow = ach * scale * min(a["volume"], b["volume"])
            if flow > 0:
                for into, source in ((a, b), (b, a)):
                    into.setdefault("airflow_from", []).append({"zone": source["name"], "flow": round(flow, 6)})

    def components(self, surfaces):
        comps, done = [], set()
        for key, s in surfaces.items():
            if self.air_boundary(s) is not None:
                continue  # an opening between zones: their air exchange (`air_boundaries`)
            if s["boundary"].lower() == "surface" and self.pair_owner(s, surfaces) is not s:
                continue  # its partner, which comes first, is the partition
            if key in done:
                continue
            done.add(key)
            obj = s["obj"]
            boundary = s["boundary"].lower()
            layers, outer, inner, _ = self.layers(s["construction"], obj, "Construction Name")
            outside = self.outside(s, boundary, outer, surfaces, done)
            net = s["area"] - sum(w["area"] for w in s["subsurfaces"])
            if net <= 1e-9:
                self.r.fail(obj, "Vertex 1 X-coordinate", f"its windows and doors ({s['area'] - net:.3f} m2) fill all "
                                                          f"of its {s['area']:.3f} m2")
            comps.append(self.component(obj.name, net, s, layers, inner, outside, outer))
            self.built_of(s["construction"], obj.name)
            if s["vertices"] is not None:  # where a traced direct sun may fall (`receivers`)
                comps[-1]["_plane"] = (s["vertices"], [w["vertices"] for w in s["subsurfaces"]
                                                       if w["vertices"] is not None])
            lit = outside["type"] == "exterior" and s["sun"] and s["vertices"] is not None
            if lit:
                comps[-1]["_polygon"] = (s["vertices"], [w["vertices"] for w in s["subsurfaces"]
                                                         if w["vertices"] is not None])
            for w in s["subsurfaces"]:
                height = w["height"]
                layers, outer, inner, glass = self.layers(w["construction"], w["obj"], "Construction Name", height)
                w_outside = self.outside(s, boundary, outer, surfaces, done, subsurface=w)
                c = self.component(w["obj"].name, w["area"], s, layers, inner, w_outside, outer)
                self.built_of(w["construction"], c["name"])
                # a window or door is its own class, not its wall's or roof's
                for face in (c["inside"], c["outside"]):
                    if "face_class" in face:
                        face["face_class"] = "wall"
                if glass is not None:
                    c["solar_transmittance"] = round(glass["tau"], 6)
                    if w_outside["type"] == "exterior" and height:
                        # under TARP EnergyPlus takes every window's inside face by ISO 15099, a
                        # simple glazing system's too (ConvectionCoefficients.cc: TypeIsWindow), and
                        # solves a layered window's panes at every step (WindowManager.cc)
                        c["window"] = {"height": round(height, 6)}
                        if glass.get("gaps") and all(g["gas"] is not None for g in glass["gaps"]):
                            c["window"]["gaps"] = glass["gaps"]
                    c["transmitted_solar_to"] = None  # set once every component is known (`receivers`)
                    if "exterior" == w_outside["type"]:
                        c["angular_transmittance"] = glass["angular"]
                    if glass["inner_alpha"] > 0 and "exterior" == w_outside["type"]:
                        c["inner_solar_absorptance"] = round(glass["inner_alpha"], 6)
                    if glass.get("absorptance") and "exterior" == w_outside["type"]:
                        c["angular_absorptance"] = glass["absorptance"]
                    if w_outside["type"] != "exterior":
                        del c["solar_transmittance"], c["transmitted_solar_to"]
                    else:
                        # seen from the room: the diffuse sun it absorbs and the part it lets out
                        c["_back"] = (glass["back_alpha"], glass["tau"] * glass["angular"]["diffuse"])
                        c["inside"].update(solar_absorptance=round(c["_back"][0], 6),
                                           diffuse_transmittance=round(c["_back"][1], 6))
                        self.incident_solar_multiplier(w["obj"], c)
                if lit and w["vertices"] is not None and w_outside["type"] == "exterior":
                    c["_polygon"] = (w["vertices"], [])
                if w["vertices"] is not None:
                    c["_plane"] = (w["vertices"], [])
                comps.append(c)
        return comps

    def built_of(self, construction, component):
        """Note that `component` is built of the IDF's Construction `construction` (the building
        file's `constructions`, which the diagnosis's effects may target as one)."""
        self.constructions.setdefault(construction.upper(), (construction, []))[1].append(component)

    def incident_solar_multiplier(self, window, c):
        """A SurfaceProperty:IncidentSolarMultiplier of an exterior window: EnergyPlus multiplies
        the sun incident on its outside by it, so that what it transmits and what its panes absorb
        scale with it; a constant one (its value times a constant schedule) scales the window's
        transmittance and absorptances. One whose schedule varies is listed, not held."""
        for o in self.r.all("SurfaceProperty:IncidentSolarMultiplier"):
            if self.r.text(o, "surface_name").upper() != window.name.upper():
                continue
            m = self.r.number(o, "incident_solar_multiplier", default=1.0, low=0, high=1)
            schedule = self.r.text(o, "incident_solar_multiplier_schedule_name")
            if schedule:
                value = self.constant_schedule_value(schedule, o, "Incident Solar Multiplier Schedule Name")
                if value is None:
                    self.not_modelled.append(f"SurfaceProperty:IncidentSolarMultiplier {window.name}: its schedule "
                                             f"{schedule!r} varies: not held (the window takes its whole sun)")
                    return
                m *= value
            c["solar_transmittance"] = round(c["solar_transmittance"] * m, 6)
            c["outside"]["solar_absorptance"] = c["outside"]["solar_absorptance"] * m
            if "inner_solar_absorptance" in c:
                c["inner_solar_absorptance"] = round(c["inner_solar_absorptance"] * m, 6)
            self.note(f"an incident solar multiplier of {m:g} on window {window.name} scales its transmittance "
                      "and absorptances")

    # ---- shading surfaces ------------------------------------------------------------------
    def shading(self, components, surfaces):
        """The building file's `shading`: every shading object's polygon (true-north coordinates, m,
        as EnergyPlus builds it), with the sunlit exterior faces it stands in front of
        (`may_shade`), and every outdoor surface of the building with the faces it and they stand
        in front of each other; those faces get their polygon (`vertices`, their windows as
        `holes`). A shading object's transmittance schedule is listed, the surface held opaque.
        Under the IDF's MinimalShadowing solar distribution EnergyPlus casts no shadow outside:
        none."""
        buildings = self.r.all("Building")
        if buildings and self.r.text(buildings[0], "solar_distribution").lower() == "minimalshadowing":
            if any(self.r.all(kind) for kind in SHADING):
                self.note("the IDF's shading surfaces cast no shadow, as EnergyPlus's MinimalShadowing solar "
                          "distribution has it")
            for c in components:
                c.pop("_polygon", None)
            return []
        shades = [(o.name, self.points(o)) for o in self.r.all("Shading:Site:Detailed")]
        shades += [(o.name, geometry.rotate_z(self.points(o), self.north))
                   for o in self.r.all("Shading:Building:Detailed")]
        for o in self.r.all("Shading:Zone:Detailed"):
            base = surfaces.get(self.r.text(o, "base_surface_name").upper())
            if base is None:
                self.r.fail(o, "Base Surface Name", f"names no heat transfer surface "
                                                    f"({self.r.text(o, 'base_surface_name')!r})")
            shades.append((o.name, self.vertices(o, self.zone_objs[base["zone"].upper()])))
        for kind in ("Shading:Site", "Shading:Building"):
            turn = self.north if kind == "Shading:Building" else 0.0
            for o in self.r.all(kind):
                corner = geometry.rotate_z([[self.r.number(o, f"starting_{a}_coordinate", default=0.0) for a in "xyz"]],
                                           turn)[0]
                shades.append((o.name, rectangle(corner, self.r.number(o, "azimuth_angle", default=0.0) + turn,
                                                 self.r.number(o, "tilt_angle", default=90.0),
                                                 self.r.number(o, "length", low=0, low_open=True),
                                                 self.r.number(o, "height", low=0, low_open=True))))
        shades += self.window_shades(surfaces)
        for kind in SHADING[:3]:
            for o in self.r.all(kind):
                if self.r.text(o, "transmittance_schedule_name"):
                    self.not_modelled.append(f"{kind} {o.name}: its transmittance schedule not held (the surface "
                                             "is opaque)")
        faces = [c for c in components if "_polygon" in c]
        normals = {c["name"]: geometry.outward_normal(c["_polygon"][0], self.ccw) for c in faces}
        out = []
        for name, polygon in shades:
            named = [c["name"] for c in faces if may_shade(polygon, c["_polygon"][0], normals[c["name"]])]
            if named:
                out.append({"name": name, "vertices": _rounded(polygon), "faces": named})
        # the building shades itself (EnergyPlus's self-shading): an outdoor surface shades a face
        # only where each stands in front of the other's plane, a ray reaching a surface from
        # behind having crossed the building before
        for s in surfaces.values():
            if s["vertices"] is None or s["boundary"].lower() != "outdoors":
                continue
            normal = geometry.outward_normal(s["vertices"], self.ccw)
            named = [c["name"] for c in faces if may_shade(s["vertices"], c["_polygon"][0], normals[c["name"]])
                     and may_shade(c["_polygon"][0], s["vertices"], normal)]
            if named:
                out.append({"name": s["obj"].name, "vertices": _rounded(s["vertices"]), "faces": named})
        shaded = {name: [s["vertices"] for s in out if name in s["faces"]] for name in normals}
        # the building file lists a face's vertices counterclockwise seen from outside
        order = (lambda p: p) if self.ccw else (lambda p: p[::-1])  # noqa: E731
        for c in components:
            polygon = c.pop("_polygon", None)
            if shaded.get(c["name"]):
                c["vertices"] = _rounded(order(polygon[0]))
                if polygon[1]:
                    c["holes"] = [_rounded(order(h)) for h in polygon[1]]
                # the shades hide sky from the face's long-wave exchange as from its diffuse sun
                # (EnergyPlus's ViewFactorSkyIR times DifShdgRatioIsoSky); what they hide is
                # exchanged with the air, as the ground's part is
                ratio = sky_diffuse_ratio(polygon[0], normals[c["name"]], shaded[c["name"]], polygon[1])
                c["outside"]["sky_view_factor"] = round(c["outside"]["sky_view_factor"] * ratio, 6)
        return out

    def window_shades(self, surfaces):
        """[(name, polygon)] of the overhangs and fins of the file's windows (`overhang`, `fin`): a
        fin object gives a left and a right fin, named as EnergyPlus names them."""
        windows = {w["obj"].name.upper(): (w, s) for s in surfaces.values() for w in s["subsurfaces"]}
        out = []
        for kind in ("Shading:Overhang", "Shading:Overhang:Projection", "Shading:Fin", "Shading:Fin:Projection"):
            for o in self.r.all(kind):
                name = self.r.text(o, "window_or_door_name")
                w, s = windows.get(name.upper(), (None, None))
                if w is None:
                    self.r.fail(o, "Window or Door Name", f"names no window or door ({name!r})")
                if w["vertices"] is None:
                    self.not_modelled.append(f"{kind} {o.name}: its window {name} has no vertices (a rectangular "
                                             "Window object): not held")
                    continue
                frame = (w["vertices"], s["azimuth"], s["tilt"])
                _, width, height, _, _ = window_frame(*frame)
                projection = kind.endswith(":Projection")
                if kind.startswith("Shading:Overhang"):
                    depth = (self.r.number(o, "depth_as_fraction_of_window_door_height", low=0) * height if projection
                             else self.r.number(o, "depth", low=0))
                    if depth > 0:  # EnergyPlus makes no surface of no depth
                        out.append((o.name, overhang(
                            *frame, self.r.number(o, "height_above_window_or_door", default=0.0),
                            self.r.number(o, "tilt_angle_from_window_door", default=90.0),
                            self.r.number(o, "left_extension_from_window_door_width", default=0.0),
                            self.r.number(o, "right_extension_from_window_door_width", default=0.0), depth)))
                    continue
                for side in ("left", "right"):
                    depth = (self.r.number(o, f"{side}_depth_as_fraction_of_window_door_width", default=0.0, low=0)
                             * width if projection else self.r.number(o, f"{side}_depth", default=0.0, low=0))
                    if depth > 0:
                        out.append((f"{o.name} {side.title()}", fin(
                            *frame, side, self.r.number(o, f"{side}_extension_from_window_door", default=0.0),
                            self.r.number(o, f"{side}_distance_above_top_of_window", default=0.0),
                            self.r.number(o, f"{side}_distance_below_bottom_of_window", default=0.0),
                            self.r.number(o, f"{side}_tilt_angle_from_window_door", default=90.0), depth)))
        return out

    def component(self, name, area, s, layers, inner, outside, outer=None):
        # each face the zones' sun can land on: (zone, its type seen from that zone, solar absorptance);
        # a partition's outer face is in the other zone (a ceiling there is its floor)
        faces = [(s["zone"], s["type"].lower(), inner["solar"])]
        flip = {"ceiling": "floor", "floor": "ceiling", "roof": "floor"}
        if outside["type"] == "zone" and outer is not None:
            faces.append((outside["zone"], flip.get(s["type"].lower(), s["type"].lower()), outer["solar"]))
            outside["solar_absorptance"] = round(outer["solar"], 6)
        if outside["type"] == "zone":
            # the zones' long-wave exchange (ScriptF) sees the outer face by its own class
            outside["face_class"] = FACE_CLASS.get(flip.get(s["type"].lower(), s["type"].lower()), "wall")
        # EnergyPlus lists a construction's layers outside first; the building file inside first
        return {"_faces": faces, "name": name, "area": round(area, 6), "tilt": round(s["tilt"], 6), "azimuth": round(s["azimuth"] % 360, 6),
                "layers": [[m, t] for m, t in reversed(layers)], "nodes": {"max_spacing": MAX_SPACING},
                "inside": {"zone": s["zone"], "h_conv": FILMS.inside_convection(s["tilt"], self.inside_algorithm(s["zone"])),
                           "h_rad": round(FILMS.radiative(inner["emissivity"], FILMS.T_inside), 4),
                           "emissivity": inner["emissivity"], "face_class": FACE_CLASS.get(s["type"].lower(), "wall"),
                           "solar_absorptance": round(inner["solar"], 6)},
                "outside": outside, "_zone": s["zone"], "_type": s["type"].lower(), "_absorbs": inner["solar"]}

    def outside(self, s, boundary, outer, surfaces, done, subsurface=None):
        obj = s["obj"]
        if boundary == "outdoors":
            h = round(FILMS.outside_convection(s["tilt"], s["height"], outer["roughness"], s["wind"], self.terrain), 4)
            # h follows the hour's wind and the face's temperature as EnergyPlus's DOE-2 has it (h
            # the constant above in the step matrix, docs/model.md 3.6); NoWind: natural alone.
            # Likewise h_rad follows the face's and the sky's temperatures, as EnergyPlus's does.
            wind = float(convection.wind_at_height(1.0, s["height"], self.terrain)) if s["wind"] else 0.0
            return {"type": "exterior", "h_conv": h, "h_rad": round(FILMS.radiative(outer["emissivity"], FILMS.T_outside), 4),
                    "solar_absorptance": outer["solar"] if s["sun"] else 0.0,
                    "sky_view_factor": round(float(sky_fraction_energyplus(s["tilt"])), 6),
                    "convection": {"algorithm": "doe2", "roughness": outer["roughness"], "wind_factor": round(wind, 6)},
                    "longwave": {"emissivity": outer["emissivity"]}}
        if boundary == "ground":
            return {"type": "boundary", "temperature": self.ground_schedule(), "h": FILMS.ground}
        if boundary == "adiabatic":
            # EnergyPlus makes an adiabatic surface its own partner (SurfaceGeometry.cc): its outer
            # face held at its inner face's temperature, the heat crossing it counted nowhere
            return {"type": "inside_face"}
        if boundary in ("surface", "zone"):
            other_name = s["other"]
            if boundary == "zone":
                zone = self.zone_objs.get(other_name.upper())
                if zone is None:
                    self.r.fail(obj, "Outside Boundary Condition Object", f"names no Zone ({other_name!r})")
                other_zone = zone.name
            else:
                other = surfaces.get(other_name.upper())
                if other is None and other_name.upper() in self.zone_objs:
                    # a Wall:Interzone (or Ceiling/Floor) may name the zone on its other side
                    other_zone = self.zone_objs[other_name.upper()].name
                elif other is None:
                    self.r.fail(obj, "Outside Boundary Condition Object", f"names no surface or zone ({other_name!r})")
                elif other is s:
                    # its own partner, as EnergyPlus makes an adiabatic surface
                    return {"type": "inside_face"}
                elif other["other"].upper() != obj.name.upper():
                    # not a pair: this face sees the other surface's zone, the other is its own component
                    self.approximated(s, f"names {other_name!r}, which names {other['other']!r} back: read as "
                                         f"facing the air of {other['zone']!r}")
                    other_zone = other["zone"]
                else:
                    done.add(other_name.upper())  # one partition for the pair
                    other_zone = other["zone"]
            h_c = FILMS.inside_convection(180.0 - s["tilt"], self.inside_algorithm(other_zone))
            return {"type": "zone", "zone": other_zone, "h_conv": h_c,
                    "h_rad": round(FILMS.radiative(outer["emissivity"], FILMS.T_inside), 4),
                    "emissivity": outer["emissivity"]}
        reader = NEAREST_BOUNDARY.get(boundary)
        if reader is not None:
            return reader(self, s)
        self.r.fail(obj, "Outside Boundary Condition", f"{s['boundary']!r} is not read (Outdoors, Ground, Adiabatic, "
                                                       "Surface, Zone and the approximated "
                                                       f"{', '.join(sorted(NEAREST_LABELS))} are)")

    # ---- boundaries the building file holds only approximately: the nearest it holds, listed ----
    def approximated(self, s, text):
        line = f"{s['obj'].obj_type} {s['obj'].name}: {text}"
        if line not in self.not_modelled:
            self.not_modelled.append(line)

    def fc_ground(self, s):
        """GroundFCfactorMethod: the face at Site:GroundTemperature:FCfactorMethod's months (EnergyPlus
        takes the weather file's 0.5 m ground temperatures where the IDF has none: the converter does
        not read the weather, and holds the building surface's ground temperature instead, said so)."""
        if self.r.all("Site:GroundTemperature:FCfactorMethod"):
            return {"type": "boundary", "temperature": self.monthly_schedule(
                "FC-factor ground temperature", "Site:GroundTemperature:FCfactorMethod", DEFAULT_GROUND), "h": FILMS.ground}
        self.note("no Site:GroundTemperature:FCfactorMethod: the F- and C-factor surfaces' ground is the building "
                  "surfaces' ground temperature (EnergyPlus takes the weather file's 0.5 m ground temperatures)")
        return {"type": "boundary", "temperature": self.ground_schedule(), "h": FILMS.ground}

    def preprocessed_ground(self, s):
        self.approximated(s, f"outside boundary {s['boundary']} read as Ground (the ground temperature schedule), "
                             "the preprocessor's temperatures not held")
        return {"type": "boundary", "temperature": self.ground_schedule(), "h": FILMS.ground}

    def foundation(self, s):
        """Foundation (Kiva's 2-D ground): the face held at the ground temperature, as Ground, through the
        construction as written; Kiva's soil, insulation and footing are not held."""
        self.approximated(s, "outside boundary Foundation (Kiva) read as Ground: the face held at the ground "
                             "temperature schedule, Kiva's soil and foundation insulation not held")
        return {"type": "boundary", "temperature": self.ground_schedule(), "h": FILMS.ground}

    def other_side_model(self, s):
        """OtherSideConditionsModel: a ground-coupled one as Ground, a ventilated cavity
        (GapConvectionRadiation) as outdoor air shading the face from the sun, with natural convection."""
        model = self.r.get("SurfaceProperty:OtherSideConditionsModel", s["other"], s["obj"],
                           "Outside Boundary Condition Object")
        kind = self.r.text(model, "type_of_modeling", "GapConvectionRadiation").lower()
        if kind in ("groundcoupledsurface", "undergroundpipingsystemsurface"):
            self.approximated(s, f"outside boundary OtherSideConditionsModel ({kind}) read as Ground")
            return {"type": "boundary", "temperature": self.ground_schedule(), "h": FILMS.ground}
        self.approximated(s, f"outside boundary OtherSideConditionsModel ({kind}) read as outdoor air behind a "
                             "shading cavity: no sun, natural convection, the cavity's own balance not held")
        return self._sheltered(s)

    def _sheltered(self, s):
        emissivity = 0.9
        return {"type": "exterior", "h_conv": round(float(convection.natural_convection(s["tilt"], FILMS.delta_T)), 4),
                "h_rad": round(FILMS.radiative(emissivity, FILMS.T_outside), 4), "solar_absorptance": 0.0,
                "sky_view_factor": 0.0}

    def other_side_coefficients(self, s):
        """OtherSideCoefficients: T = C2 T_const + C3 T_out + ... with film C1: a constant temperature
        alone is a boundary at it (through C1, or the face held at it); any other term is read as
        outdoor air without sun, said so."""
        o = self.r.get("SurfaceProperty:OtherSideCoefficients", s["other"], s["obj"], "Outside Boundary Condition Object")
        h = self.r.number(o, "combined_convective_radiative_film_coefficient", default=0.0, low=0)
        T = self.r.number(o, "constant_temperature", default=0.0)
        c_const = self.r.number(o, "constant_temperature_coefficient", default=1.0)
        others = [f for f in ("external_dry_bulb_temperature_coefficient", "ground_temperature_coefficient",
                              "wind_speed_coefficient", "zone_air_temperature_coefficient")
                  if self.r.number(o, f, default=0.0) != 0]
        if not others and _blank(_field(o, "constant_temperature_schedule_name")):
            return {"type": "boundary", "temperature": round(c_const * T, 6), "h": h if h > 0 else FILMS.ground}
        self.approximated(s, "outside boundary OtherSideCoefficients read as outdoor air without sun "
                             f"(its {', '.join(_label(f) for f in others) or 'scheduled temperature'} not held)")
        return self._sheltered(s)

    def internal_masses(self, components):
        for o in self.r.all("InternalMass"):
            zones = self._targets(o, "zone_name")  # a ZoneList gives each of its zones the whole area
            layers, _, inner, _ = self.layers(self.r.text(o, "construction_name"), o, "Construction Name")
            area = self.r.number(o, "surface_area", low=0, low_open=True)
            for zone in zones:
                # EnergyPlus's internal mass sees the zone on one face; its other face is held at
                # the first's temperature (an interzone surface that is its own partner)
                s = {"tilt": 90.0, "azimuth": 0.0, "zone": self.zone_objs[zone.upper()].name, "type": "internalmass"}
                name = o.name if len(zones) == 1 else f"{o.name} {s['zone']}"
                components.append(self.component(name, area, s, layers[::-1], inner, {"type": "inside_face"}))
                self.built_of(self.r.text(o, "construction_name"), name)

    def user_view_factors(self, zones, components, surfaces):
        """Every zone exchanges long-wave radiation by ScriptF at its faces' temperatures of each
        step, as EnergyPlus always does, with the view factors a
        ZoneProperty:UserViewFactors:BySurfaceName gives where one does. A surface is named by its
        component: a partition's second surface by its pair's."""
        for z in zones:
            z["longwave"] = "scriptf"
            z["longwave_followed"] = True
        by_zone = {z["name"].upper(): z for z in zones}
        names = {c["name"].upper(): c["name"] for c in components}
        for s in surfaces.values():
            partner = self.pair_owner(s, surfaces)
            if partner is not s:
                names[s["obj"].name.upper()] = partner["obj"].name
        for o in self.r.all("ZoneProperty:UserViewFactors:BySurfaceName"):
            fields = o.to_dict()
            label = next(k for k in fields if k.endswith("_name") and k != "name")
            for zone_name in self._targets(o, label):
                factors = by_zone[zone_name.upper()].setdefault("view_factors", {})
                for row in fields.get("view_factors") or []:
                    a, b = (names.get(str(row[k]).upper()) for k in ("from_surface", "to_surface"))
                    if a is None or b is None:
                        self.r.fail(o, "From Surface", f"names no surface of zone {zone_name!r} "
                                                       f"({row['from_surface']!r} to {row['to_surface']!r})")
                    factors.setdefault(a, {})[b] = float(row["view_factor"])

    def receivers(self, components):
        """Where the sun a zone's windows let in is absorbed, as EnergyPlus distributes it
        (`model.interior_sun`): the diffuse sun a window lets in first on the faces it sees, by its
        view factors, then what they reflect over every inside face by its area times its
        absorptance, a window's by its panes' back-side absorptance (onto its own inside face) and
        its diffuse transmittance (leaving); the direct sun on the zone's floors (its opaque faces
        if it has none), by area, each absorbing its alpha and reflecting the rest into the diffuse
        split. The direct sun's split is the window's solar_distribution, the diffuse sun's its
        diffuse_distribution; transmitted_solar_to names the largest floor. Under the Building's
        FullInteriorAndExterior distributions the direct sun is traced onto each face instead
        (`traced_beam`)."""
        traced = self.traced_distribution()
        faces = {}  # zone: [(component, type, absorptance, transmittance out)] of every face in it
        for k in components:
            for zone, kind, alpha in k["_faces"]:
                faces.setdefault(zone, []).append((k, kind, *k.get("_back", (alpha, 0.0))))
        for c in components:
            if "transmitted_solar_to" not in c:
                continue
            own = faces[c["_zone"]]
            opaque = ["_back" not in f[0] for f in own]
            floor = [o and f[1] == "floor" for o, f in zip(opaque, own)]
            floor = floor if any(floor) else opaque
            area = np.array([f[0]["area"] for f in own])
            alpha, tau = np.array([f[2] for f in own]), np.array([f[3] for f in own])
            largest = max((f for f, on in zip(own, floor) if on), key=lambda f: f[0]["area"])
            c["transmitted_solar_to"] = largest[0]["name"]
            window = next(k for k, f in enumerate(own) if f[0] is c)
            view = self.solar_view_factors(own, c["_zone"])[window]
            for field, shares in (("solar_distribution", interior_sun.beam_fractions(area, alpha, tau, floor)),
                                  ("diffuse_distribution",
                                   interior_sun.window_diffuse_fractions(area, alpha, tau, view))):
                c[field] = _named_split(own, shares)
            if traced:
                self.trace_beam(c, own, area, alpha, tau)
        for c in components:
            c.pop("_zone"), c.pop("_type"), c.pop("_absorbs"), c.pop("_faces"), c.pop("_back", None)
            c.pop("_plane", None)

    def trace_beam(self, c, own, area, alpha, tau):
        """A window's `traced_beam`: for each other face of its zone with a polygon, the split of
        the direct sun that falls on it (it absorbs its alpha, a window lets its tau_out out, the
        rest joins the diffuse split: `interior_sun.beam_fractions` with that face alone), and its
        solar_distribution the diffuse split, where the direct sun falling on none of them goes,
        as EnergyPlus adds what its back surfaces do not absorb to the zone's diffuse sun
        (SolarShading.cc, CalcInteriorSolarDistribution). The window and those faces get their
        polygons. A window without a polygon keeps its direct sun on the floor; a face no sun
        above the horizon reaches through the window (`beam_trace.may_receive_beam`) is left
        out, its share 0 at every time."""
        if not self.has_plane(c):
            return
        beam = {}
        for k, f in enumerate(own):
            if f[0] is c or not self.has_plane(f[0]) or f[0]["name"] in beam:
                continue
            if not beam_trace.may_receive_beam(self.ccw_polygon(c), self.ccw_polygon(f[0])):
                continue
            beam[f[0]["name"]] = _named_split(own, interior_sun.beam_fractions(area, alpha, tau,
                                                                              np.arange(len(own)) == k))
            self.give_polygon(f[0])
        if not beam:
            return
        self.give_polygon(c)
        c["traced_beam"] = beam
        c["solar_distribution"] = _named_split(own, interior_sun.diffuse_fractions(area, alpha, tau))

    def has_plane(self, c):
        """Whether a component has a surface polygon that faces as it does, as the building file
        checks its vertices (a window in a slightly warped wall takes the wall's tilt and azimuth,
        not its own plane's)."""
        if "_plane" not in c:
            return False
        normal = geometry.outward_normal(c["_plane"][0], self.ccw)
        return geometry.turned_from(normal, c["tilt"], c["azimuth"]) <= ORIENTATION_TOLERANCE

    def ccw_polygon(self, c):
        """A component's surface polygon (n, 3), counterclockwise seen from outside."""
        return c["_plane"][0] if self.ccw else c["_plane"][0][::-1]

    def give_polygon(self, c):
        """A component's `vertices` (and `holes`) from its surface, counterclockwise seen from
        outside, unless its shading gave them already."""
        if "vertices" in c:
            return
        order = (lambda p: p) if self.ccw else (lambda p: p[::-1])  # noqa: E731
        c["vertices"] = _rounded(self.ccw_polygon(c))
        if c["_plane"][1]:
            c["holes"] = [_rounded(order(h)) for h in c["_plane"][1]]

    @staticmethod
    def solar_view_factors(faces, zone):
        """F (n, n) between the faces of `zone` (`receivers`' entries: component, type seen from
        the zone, ...) as EnergyPlus approximates and fixes them for its solar enclosure
        (`model.longwave`), a partition's outer face looking the other way."""
        first = {}
        for k, f in enumerate(faces):
            first.setdefault(id(f[0]), k)
        # a component's first entry in its own zone is its inside face, any other its outer face
        inner = [f[0]["_zone"] == zone and first[id(f[0])] == k for k, f in enumerate(faces)]
        tilts = [f[0]["tilt"] if own else 180.0 - f[0]["tilt"] for f, own in zip(faces, inner)]
        azimuths = [f[0]["azimuth"] if own else (f[0]["azimuth"] + 180.0) % 360 for f, own in zip(faces, inner)]
        area = [f[0]["area"] for f in faces]
        classes = [FACE_CLASS.get(f[1], "wall") for f in faces]
        return longwave.fix_view_factors(area, longwave.approximate_view_factors(area, tilts, azimuths, classes))

    def traced_distribution(self):
        """Whether the Building's Solar Distribution follows the direct sun onto every face it
        reaches (FullInteriorAndExterior, with or without reflections)."""
        buildings = self.r.all("Building")
        method = self.r.text(buildings[0], "solar_distribution", "FullExterior") if buildings else "FullExterior"
        return method.lower().startswith("fullinterior")

    def list_not_modelled(self):
        for obj in self.r.doc.all_objects:
            kind = obj.obj_type
            if kind.upper() in {k.upper() for k in READ} or (kind.startswith(NOT_PHYSICS) and kind not in LISTED_RUN):
                continue
            if kind == "RunPeriodControl:DaylightSavingTime":
                self.not_modelled.append(f"{kind}: not applied; the schedules run on standard time all year")
                continue
            # an object without a name (ZoneHVAC:EquipmentConnections) is known by its first field
            name = next((str(v) for v in obj.to_dict().values() if not _blank(v)), "")
            self.not_modelled.append(f"{kind} {name}: not held by the building file")


def monthly(temps):
    """A building file's schedule of twelve monthly values."""
    ends = ("01-31", "02-28", "03-31", "04-30", "05-31", "06-30", "07-31", "08-31", "09-30", "10-31",
            "11-30", "12-31")
    if len(set(temps)) == 1:
        return {"constant": temps[0]}
    return {"days": {m: [[24, t]] for m, t in zip(MONTHS, temps)},
            "periods": [{"through": e, "week": [m] * 7} for m, e in zip(MONTHS, ends)]}


# The outside boundaries the building file holds only approximately, each read as the nearest it holds
NEAREST_BOUNDARY = {
    "groundfcfactormethod": _Converter.fc_ground, "foundation": _Converter.foundation,
    "othersideconditionsmodel": _Converter.other_side_model, "othersidecoefficients": _Converter.other_side_coefficients,
    **{b: _Converter.preprocessed_ground for b in ("groundslabpreprocessoraverage", "groundslabpreprocessorcore",
                                                   "groundslabpreprocessorperimeter", "groundbasementpreprocessoraveragewall",
                                                   "groundbasementpreprocessoraveragefloor",
                                                   "groundbasementpreprocessorupperwall",
                                                   "groundbasementpreprocessorlowerwall")}}
NEAREST_LABELS = ("GroundFCfactorMethod", "Foundation", "OtherSideConditionsModel", "OtherSideCoefficients",
                  "GroundSlabPreprocessor*", "GroundBasementPreprocessor*")

YEAR = 2017  # the calendar on which the schedules' weekdays are read (its 1 January is a Sunday)


def compress_schedule(days, year=YEAR):
    """A building file's schedule from a year of values, (days, steps per day) on `year`'s
    calendar: a constant where one value holds all year; else its distinct day profiles
    ([[until h, value], ...], equal neighbours merged) and the periods of consecutive dates over
    which each day of the week keeps one profile."""
    import datetime
    values = np.asarray(days, dtype=float)
    if np.all(values == values.flat[0]):
        return {"constant": float(values.flat[0])}
    steps = values.shape[1]
    profiles, names, periods = {}, {}, []
    week, start = {}, datetime.date(year, 1, 1)
    for k, row in enumerate(values):
        key = tuple(row)
        if key not in names:
            names[key] = f"day {len(names) + 1}"
            pairs = []
            for j, v in enumerate(row):
                if pairs and pairs[-1][1] == v:
                    pairs[-1][0] = (j + 1) * 24 / steps
                else:
                    pairs.append([(j + 1) * 24 / steps, float(v)])
            profiles[names[key]] = pairs
        date = start + datetime.timedelta(days=k)
        weekday = date.weekday()
        if week.get(weekday, names[key]) != names[key]:
            periods.append((date - datetime.timedelta(days=1), week))
            week = {}
        week[weekday] = names[key]
    periods.append((start + datetime.timedelta(days=len(values) - 1), week))
    out = []
    for end, week in periods:
        fill = next(iter(week.values()))
        out.append({"through": f"{end.month:02d}-{end.day:02d}", "week": [week.get(d, fill) for d in range(7)]})
    return {"days": profiles, "periods": out}


def _rounded(polygon):
    """A polygon's vertices as the building file writes them, m to the micrometre."""
    return [[round(float(x), 6) for x in p] for p in polygon]
