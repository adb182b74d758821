"""The records of the diagnosis benchmark whose truth is EnergyPlus (benchmarks/bench_energyplus_diagnosis.py).

A record is an ASHRAE 140 building (`BUILDINGS`: the light 600FF and the heavy 900FF, made by
examples/bestest/cases.py) with one change (`CHANGES`) made only in the IDF EnergyPlus runs, or
none; the diagnosis reads the unchanged IDF's conversion. The choices:

- the climate: Chicago O'Hare's TMY3 year, which the installed pyenergyplus package ships
  (`CLIMATE`), not the Denver year of ASHRAE 140 and the project's tests;
- the season: spring, the record from `START` for `DAYS` days, when free-floating zones swing
  most between cold nights and sunny days; the later record, on which a correction is judged, the
  same length `LATER_GAP_DAYS` after the record ends, the same change still in the truth;
- EnergyPlus runs at `ENERGYPLUS_STEPS` steps an hour from `RUN_BEFORE_DAYS` before the record,
  after its own warm-up days, to the later record's end, its sun recomputed every day (as in
  `bench_energyplus`: its default 20-day sun, up to 3.7 deg off the day's declination in April,
  alone made 0.5 C of day-to-day difference in the zone air), and reports the zone's mean air and
  the inside face temperature of every surface at each step, each stamped at its step's end in the
  weather's standard time; the sensors read every `STEP_MIN` minutes. The truth is EnergyPlus's
  answer converged in time, not its step's error: at 10-min steps 600FF's air swings 21.12 K a
  day in April, 21.75 K at 1-min steps (0.49 K RMSE between the two over a Denver year,
  docs/energyplus.md), and the faultless 600FF records took an internal mass for the difference;
- the sensors (`sensors`): the zone air and the inside faces of the south wall (behind the
  windows), the roof and the floor; Gaussian noise of `NOISE` C on every sensor, seeded by the
  record's name and draw (`benchmarks.truth.record_seed`).

A right first effect, per change (`Change.answers`, each the (effect, target) pairs of
model/effects.py's registry that name it; the targets as the converter names the IDF's zone and
surfaces):

- air change x3: the zone's infiltration, or a thermal bridge from its air to the outdoor air
  (one equation: a conductance from the air to the outdoor air);
- the walls' insulation x2 as conductive: the conductivity of one of the walls, of the walls'
  construction or of their insulation, or the zone's envelope factor;
- a furniture mass (an InternalMass): the zone's internal mass;
- the glazing's solar transmittance x0.6: a window's solar transmittance, or the windows'
  construction's;
- an office-hours gain (300 W on weekdays 08:00 to 18:00): a constant, a daily or a workday gain in
  the zone;
- the roof's solar absorptance 0.6 -> 0.9: the roof's solar absorptance;
- none: no effect added.
"""
import hashlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from benchmarks.energyplus_comparison import interval_ends
from benchmarks.truth import record_seed
from nodeforce.iotools.hourly import epw_site

ROOT = Path(__file__).resolve().parents[1]

CLIMATE = Path("data") / "weather" / "USA_IL_Chicago-OHare.Intl.AP.725300_TMY3.epw"
YEAR = 2017  # the calendar the EPW is read in, by both programs (Sunday 1 January)
START = "04-01"  # month-day of the record's first day
DAYS = 28
LATER_GAP_DAYS = 14  # from the record's end to its later record's start
RUN_BEFORE_DAYS = 14  # EnergyPlus's run starts this long before the record, after its warm-up
STEP_MIN = 10  # the sensors' interval
ENERGYPLUS_STEPS = 60  # EnergyPlus's steps an hour: its answer converged in time
NOISE = 0.1  # C
FACES = ("SOUTH WALL", "ROOF", "FLOOR")  # the inside faces measured, beside the zone air
ZONE = "CASE 600 ZONE"

# The changes' sizes
AIR_CHANGE_FACTOR = 3.0
INSULATION_FACTOR = 2.0
FURNITURE_AREA = 30.0  # m2 of InternalMass surface
FURNITURE_LAYER = (0.025, 0.15, 600.0, 1600.0)  # wood: thickness m, conductivity W/m/K, density kg/m3, J/kg/K
TRANSMITTANCE_FACTOR = 0.6
GAIN_W, GAIN_ON, GAIN_OFF, GAIN_RADIANT = 300.0, "08:00", "18:00", 0.3  # an office's equipment, weekdays
ROOF_ABSORPTANCE = 0.9


def _bestest():
    import sys
    sys.path.insert(0, str(ROOT / "examples" / "bestest"))
    import cases
    return cases


def building_document(building):
    """The idfkit document of the unchanged building: "600FF" (light) or "900FF" (heavy), sited
    where the climate's EPW was recorded (`at_weather_site`)."""
    return at_weather_site(_bestest().CASES[building](), package_weather())


def at_weather_site(doc, epw):
    """`doc` with its Site:Location replaced by the EPW's LOCATION line (name, latitude,
    longitude, time zone, elevation). EnergyPlus run on a weather file takes the file's location
    and ignores the IDF's; nodeforce converts the IDF's. ASHRAE 140's IDFs say Denver; with
    Chicago's weather, nodeforce's sun would stand 17 deg of longitude (68 min of solar time) and
    2 deg of latitude from EnergyPlus's."""
    site = epw_site(epw)
    for old in list(doc.idfobjects["Site:Location"]):
        doc.removeidfobject(old)
    doc.add("Site:Location", site["name"], {
        "latitude": site["latitude"], "longitude": site["longitude"], "time_zone": site["utc_offset"],
        "elevation": site["altitude"]})
    return doc


BUILDINGS = ("600FF", "900FF")


def _surfaces(doc, kind):
    return [s for s in doc["BuildingSurface:Detailed"] if str(s.surface_type).lower() == kind]


def _layers(doc, construction):
    c = doc.getobject("CONSTRUCTION", construction)
    fields = ["outside_layer"] + [f"layer_{k}" for k in range(2, 11)]
    return [getattr(c, f) for f in fields if getattr(c, f, None)]


def _own_copy(doc, kind, surfaces, layer_index, suffix):
    """Give `surfaces` their own construction whose layer `layer_index` is a copy of the material
    there (named with `suffix`): a change to it then reaches those surfaces alone, not the others
    that share the material. Returns the copied material."""
    construction = surfaces[0].construction_name
    old = doc.getobject("CONSTRUCTION", construction)
    layers = _layers(doc, construction)
    material = doc.getobject(kind, layers[layer_index])
    fields = {k: v for k, v in material.to_dict().items() if k != "name" and v not in (None, "")}
    new_material = doc.add(material.obj_type, f"{material.name} {suffix}", fields)
    layers[layer_index] = new_material.name
    names = ["outside_layer"] + [f"layer_{k}" for k in range(2, len(layers) + 1)]
    doc.add("Construction", f"{old.name} {suffix}", dict(zip(names, layers)))
    for s in surfaces:
        s.construction_name = f"{old.name} {suffix}"
    return new_material


def wall_insulation(doc):
    """(material, layer index) of the exterior walls' insulation: their least conductive layer."""
    walls = [s for s in _surfaces(doc, "wall") if str(s.outside_boundary_condition).lower() == "outdoors"]
    layers = _layers(doc, walls[0].construction_name)
    k = [float(doc.getobject("MATERIAL", m).conductivity) if doc.getobject("MATERIAL", m) else np.inf
         for m in layers]
    return walls, int(np.argmin(k))


def more_air_change(doc):
    for o in doc["ZoneInfiltration:DesignFlowRate"]:
        o.air_changes_per_hour = float(o.air_changes_per_hour) * AIR_CHANGE_FACTOR


def more_conductive_walls(doc):
    walls, index = wall_insulation(doc)
    material = _own_copy(doc, "MATERIAL", walls, index, "X2")
    material.conductivity = float(material.conductivity) * INSULATION_FACTOR


def furniture(doc):
    thickness, conductivity, density, specific_heat = FURNITURE_LAYER
    doc.add("Material", "FURNITURE WOOD", {"roughness": "MediumSmooth", "thickness": thickness,
                                           "conductivity": conductivity, "density": density,
                                           "specific_heat": specific_heat, "thermal_absorptance": 0.9,
                                           "solar_absorptance": 0.6, "visible_absorptance": 0.6})
    doc.add("Construction", "FURNITURE", {"outside_layer": "FURNITURE WOOD"})
    doc.add("InternalMass", "FURNITURE", {"construction_name": "FURNITURE", "zone_or_zonelist_name": ZONE,
                                          "surface_area": FURNITURE_AREA})


def darker_glass(doc):
    for pane in doc["WindowMaterial:Glazing"]:
        pane.solar_transmittance_at_normal_incidence = (float(pane.solar_transmittance_at_normal_incidence)
                                                        * TRANSMITTANCE_FACTOR)


def office_gain(doc):
    doc.add("Schedule:Compact", "OFFICE HOURS", {"data": [
        {"field": "Through: 12/31"}, {"field": "For: Weekdays"},
        {"field": f"Until: {GAIN_ON}"}, {"field": "0"},
        {"field": f"Until: {GAIN_OFF}"}, {"field": "1"},
        {"field": "Until: 24:00"}, {"field": "0"},
        {"field": "For: AllOtherDays"}, {"field": "Until: 24:00"}, {"field": "0"}]})
    doc.add("ElectricEquipment", "OFFICE EQUIPMENT", {
        "zone_or_zonelist_name": ZONE, "schedule_name": "OFFICE HOURS", "design_level_calculation_method": "EquipmentLevel",
        "design_level": GAIN_W, "fraction_latent": 0.0, "fraction_radiant": GAIN_RADIANT, "fraction_lost": 0.0})


def darker_roof(doc):
    roof = _surfaces(doc, "roof")
    material = _own_copy(doc, "MATERIAL", roof, 0, "DARK")
    material.solar_absorptance = ROOF_ABSORPTANCE


@dataclass(frozen=True)
class Change:
    """A change made in the IDF EnergyPlus runs: what it is, the edit (`edit(doc)`, in place) and
    the (effect, target) pairs a right first effect names."""
    label: str
    edit: object
    answers: tuple


WALLS = ("SOUTH WALL", "EAST WALL", "NORTH WALL", "WEST WALL")
WINDOWS = ("SOUTH WINDOW WEST", "SOUTH WINDOW EAST")
# the walls' construction and insulation as groups (docs/model.md section 7: a target shared by
# several surfaces), which the converter makes of examples/bestest/cases.py's IDFs
WALL_GROUPS = ("construction:LIGHT WALL", "construction:HEAVY WALL", "material:WALL FIBERGLASS QUILT",
               "material:FOAM INSULATION")
CHANGES = {
    "air-change": Change("air change x3", more_air_change, (("infiltration", ZONE), ("thermal_bridge", ZONE))),
    "insulation": Change("walls' insulation conductivity x2", more_conductive_walls,
                         tuple(("conductivity", w) for w in WALLS + WALL_GROUPS) + (("envelope_conductance", ZONE),)),
    "furniture": Change("furniture (InternalMass)", furniture, (("internal_mass", ZONE),)),
    "glass": Change("glazing's solar transmittance x0.6", darker_glass,
                    tuple(("solar_transmittance", w) for w in WINDOWS + ("construction:DOUBLE CLEAR",))),
    "gain": Change("office-hours gain 300 W", office_gain,
                   (("internal_gain", ZONE), ("daily_gain", ZONE), ("workday_gain", ZONE))),
    "roof": Change("roof's solar absorptance 0.6 -> 0.9", darker_roof, (("solar_absorptance", "ROOF"),)),
    "none": Change("none", None, ()),
}


@dataclass(frozen=True)
class Spec:
    """One record: a building and a change."""
    building: str
    change: str

    @property
    def name(self):
        return f"{self.building}/{self.change}"

    @property
    def answers(self):
        return CHANGES[self.change].answers

    @property
    def label(self):
        return CHANGES[self.change].label


SPECS = [Spec(b, c) for b in BUILDINGS for c in CHANGES]
SPECS_BY_NAME = {s.name: s for s in SPECS}


def changed_document(spec):
    """The idfkit document of the record's truth: the building with its change (none for "none")."""
    doc = building_document(spec.building)
    edit = CHANGES[spec.change].edit
    if edit is not None:
        edit(doc)
    return doc


# -- the periods ------------------------------------------------------------------------------

def record_start():
    return pd.Timestamp(f"{YEAR}-{START}")


def periods():
    """{"record", "later"}: (first, last) naive local standard times of each record's samples; and
    "run": the (first day, last day) EnergyPlus simulates."""
    step = pd.Timedelta(minutes=STEP_MIN)
    start = record_start()
    end = start + pd.Timedelta(days=DAYS)
    later_start = end + pd.Timedelta(days=LATER_GAP_DAYS)
    later_end = later_start + pd.Timedelta(days=DAYS)
    return {"record": (start + step, end), "later": (later_start + step, later_end),
            "run": (start - pd.Timedelta(days=RUN_BEFORE_DAYS), later_end - pd.Timedelta(days=1))}


# -- EnergyPlus ----------------------------------------------------------------------------------

def package_weather():
    """The climate's EPW inside the installed pyenergyplus package."""
    import pyenergyplus
    return Path(pyenergyplus.__file__).parent / CLIMATE


def utc_offset(epw):
    """The EPW's standard time's offset from UTC (h), its LOCATION line's ninth field."""
    return epw_site(epw)["utc_offset"]


def run_document(doc):
    """The document EnergyPlus runs: `benchmarks/bench_energyplus.py`'s free-floating 25.2 copy,
    over `periods()["run"]` at `ENERGYPLUS_STEPS` an hour, reporting the zone's mean air and every
    surface's inside face temperature at each step."""
    import sys
    if str(ROOT / "benchmarks") not in sys.path:
        sys.path.insert(0, str(ROOT / "benchmarks"))
    from bench_energyplus import to_energyplus_25
    new = to_energyplus_25(doc)
    for kind in ("RunPeriod", "Output:Variable", "Timestep"):
        for obj in list(new[kind]):
            new.removeidfobject(obj)
    first, last = periods()["run"]
    new.add("Timestep", "", {"number_of_timesteps_per_hour": ENERGYPLUS_STEPS})
    new.add("RunPeriod", "record", {
        "begin_month": first.month, "begin_day_of_month": first.day, "begin_year": YEAR,
        "end_month": last.month, "end_day_of_month": last.day, "end_year": YEAR,
        "use_weather_file_holidays_and_special_days": "No", "use_weather_file_daylight_saving_period": "No",
        "apply_weekend_holiday_rule": "No", "use_weather_file_rain_indicators": "No",
        "use_weather_file_snow_indicators": "No"})
    for variable in ("Zone Mean Air Temperature", "Surface Inside Face Temperature"):
        new.add("Output:Variable", "", {"key_value": "*", "variable_name": variable, "reporting_frequency": "Timestep"})
    return new


def simulate_energyplus(doc, epw):
    """DataFrame of EnergyPlus's run of `doc` (`run_document`): columns the zone's name (its mean
    air) and each surface's name (its inside face), C, indexed by the naive local standard time of
    each step's end."""
    return read_steps(energyplus_table(run_document(doc), epw))


def energyplus_table(doc, epw):
    """EnergyPlus's eplusout.csv table of its run of `doc` as it is (its outputs and run period
    the document's own) on the weather `epw`. EnergyPlus works in a temporary folder, removed
    however the run ends."""
    import idfkit
    from nodeforce.runtime import tempdirs
    from pyenergyplus.api import EnergyPlusAPI
    with tempdirs.folder("energyplus") as folder:
        idf = Path(folder) / "model.idf"
        idfkit.save_idf(doc, str(idf))
        api = EnergyPlusAPI()
        state = api.state_manager.new_state()
        api.runtime.set_console_output_status(state, False)  # its lines would bury the progress bar
        try:
            code = api.runtime.run_energyplus(state, ["-w", str(epw), "-d", str(folder), "-r", str(idf)])
        finally:
            api.state_manager.delete_state(state)
        if code != 0:
            errors = (Path(folder) / "eplusout.err").read_text(errors="replace")[-2000:]
            raise RuntimeError(f"EnergyPlus failed on {doc_name(doc)}: {errors}")
        return pd.read_csv(Path(folder) / "eplusout.csv")


def doc_name(doc):
    buildings = list(doc["Building"])
    return buildings[0].name if buildings else "the model"


def read_steps(table):
    """The timestep outputs of an eplusout.csv table: columns named by their key (upper case),
    the index the end of each step in `YEAR` (`energyplus_comparison.interval_ends`)."""
    columns = {c.split(":")[0].strip().upper(): table[c].to_numpy(float) for c in table.columns
               if "Zone Mean Air Temperature" in c or "Surface Inside Face Temperature" in c}
    return pd.DataFrame(columns, index=interval_ends(table["Date/Time"], YEAR))


# -- the records ------------------------------------------------------------------------------------

def sensors(building):
    """{measurement column: what it reads in EnergyPlus's table} of a converted building: `T<id>`
    of the zone's air node and of the inside face (the first node) of each of `FACES`."""
    names = building.node_names()
    zone = building.zone(ZONE)
    out = {f"T{zone.air_node}": ZONE}
    for face in FACES:
        node, = [i for i, n in names.items() if n == f"{face} at 0.000 m"]
        out[f"T{node}"] = face
    return out


def sample(steps, which, columns, offset_h):
    """The record `which` ("record" or "later") of EnergyPlus's steps: the `columns`
    ({measurement column: EnergyPlus key}) at the record's times, every `STEP_MIN` minutes, tz-aware
    at `offset_h`; KeyError where EnergyPlus has no step ending at one of them."""
    first, last = periods()[which]
    part = steps.loc[pd.date_range(first, last, freq=f"{STEP_MIN}min"), list(columns.values())]
    part.columns = list(columns)
    tz = pd.Timestamp(0, tz="UTC").tz_convert(f"Etc/GMT{-int(offset_h):+d}").tz
    part.index = part.index.tz_localize(tz).rename("time")
    return part


def noisy(clean, name, draw, noise=NOISE):
    """`clean` with Gaussian noise of sd `noise` (C), seeded by the record's name and draw."""
    rng = np.random.default_rng(record_seed(name, draw))
    return pd.DataFrame(clean.to_numpy() + rng.normal(0.0, noise, clean.shape), index=clean.index,
                        columns=clean.columns)


def write_measurements(frame, path):
    """A measurements CSV (docs/guide.md): `time` ISO 8601 with its offset, then the columns."""
    out = frame.copy()
    out.index = [t.isoformat() for t in out.index]
    out.index.name = "time"
    out.to_csv(path, float_format="%.4f")


def spec_digest(spec, code):
    """A digest of what makes a record's result: its spec, the module's settings and the code."""
    settings = repr((spec, CLIMATE, YEAR, START, DAYS, LATER_GAP_DAYS, RUN_BEFORE_DAYS, STEP_MIN, ENERGYPLUS_STEPS,
                     NOISE, FACES))
    return hashlib.sha1((settings + code).encode()).hexdigest()[:12]
