"""nodeforce convert (iotools/energyplus.py) on what EnergyPlus models carry beyond case 600: fields
found through each version's IDD, schedules with holidays, bad files, autocalculated volumes, zone
lists, equivalent F- and C-factor constructions, fill gases, approximated boundaries and interzone
pairs; each against a hand calculation from the IDF text or EnergyPlus's own equations."""
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from nodeforce.api import convert_idf
from nodeforce.iotools import energyplus as E
from nodeforce.iotools.idf_text import unterminated_object
from nodeforce.model import glazing
from nodeforce.model.errors import InputError

ROOT = Path(__file__).resolve().parents[1]
CASE600 = ROOT / "examples" / "bestest" / "case600.idf"
MULTIZONE = ROOT / "examples" / "multizone" / "three_zones.idf"
TEXT = CASE600.read_text()
# case 600 up to its zone: the site, rules, materials and constructions
HEADER = TEXT[:TEXT.index("Zone,\n  CASE 600 ZONE")]


def box(name, zone, L=8.0, W=6.0, H=2.7, floor="Ground", floor_object="", floor_construction="LIGHT FLOOR"):
    """The six BuildingSurface:Detailed of an L x W x H box zone, counterclockwise seen from outside."""
    faces = {
        "S": ("Wall", "LIGHT WALL", "Outdoors", "", [(0, 0, H), (0, 0, 0), (L, 0, 0), (L, 0, H)]),
        "E": ("Wall", "LIGHT WALL", "Outdoors", "", [(L, 0, H), (L, 0, 0), (L, W, 0), (L, W, H)]),
        "N": ("Wall", "LIGHT WALL", "Outdoors", "", [(L, W, H), (L, W, 0), (0, W, 0), (0, W, H)]),
        "W": ("Wall", "LIGHT WALL", "Outdoors", "", [(0, W, H), (0, W, 0), (0, 0, 0), (0, 0, H)]),
        "F": ("Floor", floor_construction, floor, floor_object, [(L, W, 0), (L, 0, 0), (0, 0, 0), (0, W, 0)]),
        "R": ("Roof", "LIGHT ROOF", "Outdoors", "", [(0, W, H), (0, 0, H), (L, 0, H), (L, W, H)]),
    }
    out = []
    for key, (kind, construction, boundary, other, vertices) in faces.items():
        sun = "SunExposed" if boundary == "Outdoors" else "NoSun"
        wind = "WindExposed" if boundary == "Outdoors" else "NoWind"
        points = ",\n  ".join(f"{x}, {y}, {z}" for x, y, z in vertices)
        out.append(f"BuildingSurface:Detailed,\n  {name} {key},\n  {kind},\n  {construction},\n  {zone},\n  {boundary},\n"
                   f"  {other},\n  {sun},\n  {wind},\n  autocalculate,\n  4,\n  {points};\n")
    return "".join(out)


def zone(name, x=0.0, volume="autocalculate", multiplier=1):
    return f"Zone,\n  {name},\n  0,\n  {x},\n  0,\n  0,\n  1,\n  {multiplier},\n  autocalculate,\n  {volume};\n"


def write(tmp_path, text, name="model.idf"):
    path = tmp_path / name
    path.write_text(text)
    return path


# ---- fields through each version's IDD ------------------------------------------------------
READ_FIELDS = {  # every field the converter asks of an object kind, named as 8.9's IDD names it
    "Lights": ["zone_or_zonelist_name", "schedule_name", "design_level_calculation_method", "lighting_level",
               "watts_per_zone_floor_area", "watts_per_person", "return_air_fraction", "fraction_radiant", "fraction_visible"],
    "ElectricEquipment": ["zone_or_zonelist_name", "design_level", "watts_per_zone_floor_area", "watts_per_person",
                          "fraction_latent", "fraction_radiant", "fraction_lost"],
    "GasEquipment": ["zone_or_zonelist_name", "design_level", "power_per_zone_floor_area", "power_per_person"],
    "OtherEquipment": ["zone_or_zonelist_name", "design_level", "power_per_zone_floor_area", "power_per_person"],
    "People": ["zone_or_zonelist_name", "number_of_people_schedule_name", "number_of_people_calculation_method",
               "number_of_people", "people_per_zone_floor_area", "zone_floor_area_per_person", "fraction_radiant",
               "sensible_heat_fraction", "activity_level_schedule_name"],
    "ZoneInfiltration:DesignFlowRate": ["zone_or_zonelist_name", "design_flow_rate", "flow_per_zone_floor_area",
                                        "flow_per_exterior_surface_area", "air_changes_per_hour",
                                        "constant_term_coefficient"],
    "ZoneVentilation:DesignFlowRate": ["zone_or_zonelist_name", "flow_rate_per_zone_floor_area", "air_changes_per_hour",
                                       "minimum_indoor_temperature", "maximum_wind_speed"],
    "InternalMass": ["construction_name", "zone_name", "surface_area"],
    "Zone": ["multiplier", "ceiling_height", "volume", "floor_area", "zone_inside_convection_algorithm"],
    "BuildingSurface:Detailed": ["surface_type", "construction_name", "zone_name", "outside_boundary_condition",
                                 "outside_boundary_condition_object", "view_factor_to_ground"],
    "WindowMaterial:Glazing": ["optical_data_type", "solar_transmittance_at_normal_incidence",
                               "front_side_solar_reflectance_at_normal_incidence"],
    "WindowMaterial:GasMixture": ["number_of_gases_in_mixture", "gas_1_type", "gas_1_fraction"],
    "Construction:FfactorGroundFloor": ["f_factor", "area", "perimeterexposed"],
    "Construction:CfactorUndergroundWall": ["c_factor", "height"],
}


@pytest.mark.parametrize("version", [(8, 9, 0), (9, 6, 0), (22, 1, 0), (25, 2, 0)])
def test_every_field_read_is_found_in_the_files_own_idd(version):
    """Each field is found in the IDD of the file's version by aligning its field list with
    8.9's; the renames of 9.6 and 25.x (`Watts per Floor Area`, `Flow Rate per Exterior Surface
    Area`) come from the IDDs, not from a table."""
    for kind, fields in READ_FIELDS.items():
        own = E._idd_fields(kind, version)
        names = E._field_names(kind, version)
        for field in fields:
            assert names.get(field, field) in own, (kind, field, version)
    assert E._field_names("ElectricEquipment", (25, 2, 0))["watts_per_zone_floor_area"] == "watts_per_floor_area"
    assert E._field_names("ZoneInfiltration:DesignFlowRate", (25, 2, 0))["flow_per_exterior_surface_area"] == \
        "flow_rate_per_exterior_surface_area"
    assert E._field_names("InternalMass", (25, 2, 0))["zone_name"] == "zone_or_zonelist_name"


def test_a_25_2_model_reads_its_renamed_methods(tmp_path):
    """three_zones.idf brought to 25.2, its infiltration Flow/ExteriorArea and its lights
    Watts/Area: the rate and the power are the IDD-named fields' values."""
    import idfkit
    from benchmarks.bench_energyplus import to_energyplus_25
    doc = to_energyplus_25(idfkit.load_idf(str(MULTIZONE)))
    (inf,) = [o for o in doc.all_objects if o.obj_type == "ZoneInfiltration:DesignFlowRate"]
    inf.design_flow_rate_calculation_method = "Flow/ExteriorArea"
    inf.flow_rate_per_exterior_surface_area = 0.0003
    inf.air_changes_per_hour = None
    path = tmp_path / "25.idf"
    idfkit.save_idf(doc, str(path))
    b = convert_idf(path)
    office = b.zone("EAST OFFICE")
    exterior = sum(c.area for c in b.components
                   if c.inside.zone == "EAST OFFICE" and getattr(c.outside, "h_conv", None) is not None
                   and type(c.outside).__name__ == "Exterior")
    assert office.air_change_rate * office.volume == pytest.approx(0.0003 * 3600 * exterior, rel=1e-6)


# ---- schedules -------------------------------------------------------------------------------
HOLIDAYS = "".join(f"RunPeriodControl:SpecialDays,\n  Day {k},\n  {m}/{d},\n  1,\n  Holiday;\n"
                   for k, (m, d) in enumerate([(1, 2), (5, 29), (7, 4), (9, 4), (11, 23), (12, 25)]))
OCCUPANCY = """Schedule:Compact,
  OCC,
  Fraction,
  Through: 12/31,
  For: Weekdays,
  Until: 08:00, 0.0,
  Until: 18:00, 1.0,
  Until: 24:00, 0.1,
  For: Holiday,
  Until: 24:00, 0.05,
  For: AllOtherDays,
  Until: 24:00, 0.2;
"""


def test_schedules_evaluated_by_day_are_idfkits_values(tmp_path):
    """The day-by-day evaluation is idfkit's own, step for step, holidays included."""
    import idfkit
    import idfkit.schedules as S
    path = write(tmp_path, HEADER + OCCUPANCY + HOLIDAYS)
    doc = idfkit.load_idf(str(path))
    (occ,) = [o for o in doc.all_objects if o.obj_type == "Schedule:Compact"]
    mine = E._DaySchedules(doc).of(occ, 4).ravel()
    theirs = np.array(S.values(occ, year=E.YEAR, timestep=4, document=doc))
    assert np.array_equal(mine, theirs)
    # 2017-07-04, a Tuesday, is a holiday at 0.05 all day
    day = (np.datetime64("2017-07-04") - np.datetime64("2017-01-01")).astype(int)
    assert set(mine.reshape(-1, 96)[day]) == {0.05}


def test_a_for_field_reads_each_day_type_singular_or_plural(tmp_path):
    """EnergyPlus reads "For: Weekday" as "Weekdays" (and Saturdays, Holidays, AllOtherDay ...):
    the 2019 sit-down restaurant's dining lights, "For: Weekday" 13.693 h of full light a day
    (its Until fields by hand), Saturday 12.857 h, "For: Sunday Holidays AllOtherDays" 10.511 h,
    over 2017 (53 Sundays, 52 Saturdays, 260 weekdays, the 6 holidays here all weekdays):
    (254 x 13.693 + 52 x 12.857 + 59 x 10.511) / 24 / 365 = 0.5442, as EnergyPlus's Zone Lights
    Total Heating Rate over the year gives it (1304 W of 2401 W, 0.543, on the restaurant's own
    holidays); a weekday read as no day falls to the Sunday profile (0.452). A Saturday of "For:
    Saturdays" takes its own profile."""
    import idfkit
    text = HEADER + HOLIDAYS + """Schedule:Compact,
  DINING,
  Fraction,
  Through: 12/31,
  For: Weekday,
  Until: 1:00,0.1407843825, Until: 5:00,0.15, Until: 6:00,0.18771251, Until: 8:00,0.37542502,
  Until: 10:00,0.56313753, Until: 22:00,0.844706295, Until: 23:00,0.469281275, Until: 24:00,0.281568765,
  For: Saturdays,
  Until: 1:00,0.18771251, Until: 6:00,0.15, Until: 8:00,0.281568765, Until: 10:00,0.56313753,
  Until: 17:00,0.75085004, Until: 22:00,0.844706295, Until: 23:00,0.469281275, Until: 24:00,0.281568765,
  For: SummerDesignDay, Until: 24:00,1,
  For: Sunday Holidays AllOtherDays,
  Until: 1:00,0.18771251, Until: 6:00,0.15, Until: 8:00,0.281568765, Until: 10:00,0.469281275,
  Until: 16:00,0.656993785, Until: 22:00,0.56313753, Until: 23:00,0.469281275, Until: 24:00,0.281568765;
"""
    path = write(tmp_path, text)
    doc = idfkit.load_idf(str(path))
    (dining,) = [o for o in doc.all_objects if o.obj_type == "Schedule:Compact"]
    days = E._DaySchedules(doc).of(dining, 1)
    assert days.mean() == pytest.approx((254 * 13.693 + 52 * 12.857 + 59 * 10.511) / 24 / 365, abs=1e-4)
    assert days[1].sum() == pytest.approx(10.511, abs=1e-3)  # 2017-01-02, a Monday and a holiday
    assert days[3].sum() == pytest.approx(13.693, abs=1e-3)  # Wednesday
    assert days[6].sum() == pytest.approx(12.857, abs=1e-3)  # Saturday
    assert days[7].sum() == pytest.approx(10.511, abs=1e-3)  # Sunday
    assert E.compact_day_types("For: Weedends WinterDesignDay") == {"WinterDesignDay"}


def test_a_holiday_takes_no_weekday_rule(tmp_path):
    """EnergyPlus gives a holiday its own day type, in place of its day of the week's: a schedule
    that names no Holiday, "For: Weekdays", "For: Saturday", "For: AllOtherDays" (the 2004
    reference offices' gains), runs its AllOtherDays profile on a Tuesday holiday (2017-07-04) and
    a Monday one (2017-01-02), and its weekday profile on the Wednesday after. So does a
    Schedule:Week:Compact of the same day lists. idfkit's own evaluation gives those holidays the
    weekday profile."""
    import idfkit
    import idfkit.schedules as S
    text = HEADER + HOLIDAYS + """Schedule:Compact,
  EQUIP,
  Fraction,
  Through: 12/31,
  For: Weekdays,
  Until: 08:00, 0.4,
  Until: 18:00, 0.9,
  Until: 24:00, 0.4,
  For: Saturday,
  Until: 24:00, 0.3,
  For: AllOtherDays,
  Until: 24:00, 0.2;
Schedule:Day:Hourly,
  WORKDAY,
  Fraction,
  0.4, 0.4, 0.4, 0.4, 0.4, 0.4, 0.4, 0.4, 0.9, 0.9, 0.9, 0.9,
  0.9, 0.9, 0.9, 0.9, 0.9, 0.9, 0.4, 0.4, 0.4, 0.4, 0.4, 0.4;
Schedule:Day:Hourly,
  RESTDAY,
  Fraction,
  0.2, 0.2, 0.2, 0.2, 0.2, 0.2, 0.2, 0.2, 0.2, 0.2, 0.2, 0.2,
  0.2, 0.2, 0.2, 0.2, 0.2, 0.2, 0.2, 0.2, 0.2, 0.2, 0.2, 0.2;
Schedule:Week:Compact,
  EQUIP WEEK,
  For: Weekdays,
  WORKDAY,
  For: AllOtherDays,
  RESTDAY;
"""
    doc = idfkit.load_idf(str(write(tmp_path, text)))
    schedules = E._DaySchedules(doc)
    compact = schedules.of(doc.getobject("Schedule:Compact", "EQUIP"), 1)
    week = schedules.of(doc.getobject("Schedule:Week:Compact", "EQUIP WEEK"), 1)
    workday = np.array([0.4] * 8 + [0.9] * 10 + [0.4] * 6)
    for days in (compact, week):
        assert np.allclose(days[1], 0.2)  # 2017-01-02, a Monday and a holiday
        assert np.allclose(days[184], 0.2)  # 2017-07-04, a Tuesday and a holiday
        assert np.allclose(days[185], workday)  # 2017-07-05, a Wednesday
    assert np.allclose(compact[6], 0.3)  # 2017-01-07, a Saturday
    theirs = np.array(S.values(doc.getobject("Schedule:Compact", "EQUIP"), year=E.YEAR, timestep=1, document=doc))
    assert np.allclose(theirs.reshape(-1, 24)[184], workday)


def twenty_zones():
    text = HEADER + OCCUPANCY + HOLIDAYS
    for k in range(20):
        name = f"Z{k}"
        text += zone(name, x=10.0 * k) + box(name, name)
        text += (f"People,\n  {name} people,\n  {name},\n  OCC,\n  People,\n  2,\n  ,\n  ,\n  0.3,\n  autocalculate,\n"
                 f"  ACTIVITY;\n")
        text += (f"Lights,\n  {name} lights,\n  {name},\n  OCC,\n  Watts/Area,\n  ,\n  10,\n  ,\n  0,\n  0.4,\n"
                 f"  0.2,\n  1;\n")
    return text + "Schedule:Constant,\n  ACTIVITY,\n  ,\n  120;\n"


def test_a_twenty_zone_model_finds_its_holidays_once(tmp_path, monkeypatch):
    """20 zones, each with a person and lights on a schedule with six holidays: idfkit's values()
    finds the holidays again at every time step (114 s for the 2004 small office); the converter
    finds them once for the whole file."""
    import idfkit.schedules.holidays as holidays
    found, get_holidays = [], holidays.get_holidays
    monkeypatch.setattr(holidays, "get_holidays", lambda *args, **kw: found.append(args) or get_holidays(*args, **kw))
    path = write(tmp_path, twenty_zones())
    b = convert_idf(path)
    assert len(found) == 1
    assert len(b.zones) == 20
    lights = {g.name: g for g in b.zone("Z7").gains}["Z7 lights"]
    assert lights.power == pytest.approx(10 * 48.0)  # W/m2 x the 8 x 6 m floor


# ---- bad input ----------------------------------------------------------------------------
def test_a_truncated_file_is_refused_before_anything_parses_it(tmp_path):
    """idfkit's object pattern backtracks exponentially on an open tail; the command refuses the
    file in one line before it loads idfkit, numpy or the model."""
    path = write(tmp_path, "Version,9.6;\nZone,\n  A,\n  0,\n  0,\n  0,\n  0,\n  1\n")
    with pytest.raises(InputError, match="no closing ';'") as e:
        convert_idf(path)
    assert "\n" not in str(e.value) and str(path) in str(e.value) and "Zone" in str(e.value)
    probe = ("import sys; from nodeforce.__main__ import main; status = main(sys.argv[1:]); "
             "loaded = [m for m in ('idfkit', 'numpy', 'nodeforce.iotools.energyplus') "
             "if type(sys.modules.get(m)).__name__ == 'module']; print(status, loaded)")
    done = subprocess.run([sys.executable, "-c", probe, "convert", path, "-o", tmp_path / "t.json"],
                          capture_output=True, text=True, timeout=60)
    assert done.stdout.split("\n")[0] == "2 []" and len(done.stderr.strip().splitlines()) == 1


def test_a_closed_file_with_a_comment_after_its_last_object_is_read():
    assert unterminated_object("Version,9.6;\n! the end, no more objects\n  \n") is None
    assert unterminated_object("Version,9.6;\nZone, A ! a comment; with a semicolon\n") == "Zone, A"


def test_an_unknown_version_is_refused(tmp_path):
    path = write(tmp_path, TEXT.replace("Version,\n  9.3;", "Version,\n  99.1;"))
    with pytest.raises(InputError, match="99.1 is newer than any IDD"):
        convert_idf(path)


def test_a_non_planar_wall_is_refused_and_a_slightly_warped_one_listed(tmp_path):
    far = TEXT.replace("  8, 0, 2.7;                    !- Vertex 4 {m}", "  8, 3, 2.7;                    !- Vertex 4 {m}", 1)
    # the Newell plane fits all four vertices: 3 m on one leaves 0.65 m on each off it
    with pytest.raises(InputError, match="SOUTH WALL.*0.647 m off the surface's plane"):
        convert_idf(write(tmp_path, far, "far.idf"))
    near = TEXT.replace("  8, 0, 2.7;                    !- Vertex 4 {m}", "  8, 0.15, 2.7;                 !- Vertex 4 {m}", 1)
    lines = convert_idf(write(tmp_path, near, "near.idf")).data["not_modelled"]
    assert any(line.startswith("BuildingSurface:Detailed SOUTH WALL: not planar") for line in lines)


# ---- zones ----------------------------------------------------------------------------------
def test_a_zero_volume_is_autocalculated_by_the_divergence_theorem(tmp_path):
    path = write(tmp_path, HEADER + zone("Z", volume=0) + box("Z", "Z", 8, 6, 2.7))
    assert convert_idf(path).zone("Z").volume == pytest.approx(8 * 6 * 2.7)


def test_an_open_zone_takes_floor_area_times_height(tmp_path):
    """Without its roof the box closes nothing: EnergyPlus's floor area x ceiling height."""
    text = box("Z", "Z", 8, 6, 2.7)
    text = text[:text.index("BuildingSurface:Detailed,\n  Z R")]
    assert convert_idf(write(tmp_path, HEADER + zone("Z") + text)).zone("Z").volume == pytest.approx(8 * 6 * 2.7)


def test_rectangular_surfaces_autocalculate_the_volume(tmp_path):
    """A zone of Wall:Exterior, Roof and Floor:GroundContact 5 x 4 m, 3 m high: 60 m3."""
    walls = "".join(f"Wall:Exterior,\n  W{k},\n  LIGHT WALL,\n  Z,\n  {az},\n  90,\n  {x},\n  {y},\n  0,\n  {L},\n  3;\n"
                    for k, (az, x, y, L) in enumerate([(180, 0, 0, 5), (90, 5, 0, 4), (0, 5, 4, 5), (270, 0, 4, 4)]))
    text = (HEADER + zone("Z") + walls + "Roof,\n  R,\n  LIGHT ROOF,\n  Z,\n  180,\n  0,\n  0,\n  4,\n  3,\n  5,\n  4;\n"
            + "Floor:GroundContact,\n  F,\n  LIGHT FLOOR,\n  Z,\n  180,\n  180,\n  5,\n  0,\n  0,\n  5,\n  4;\n")
    assert convert_idf(write(tmp_path, text)).zone("Z").volume == pytest.approx(60.0)


def test_a_zone_multiplier_is_listed_not_refused(tmp_path):
    b = convert_idf(write(tmp_path, HEADER + zone("Z", multiplier=4) + box("Z", "Z")))
    assert any(line.startswith("Zone Z: multiplier 4 not held") for line in b.data["not_modelled"])


def test_internal_mass_of_a_zone_list_goes_to_each_zone(tmp_path):
    text = (HEADER + zone("A") + box("A", "A") + zone("B", x=20) + box("B", "B")
            + "ZoneList,\n  BOTH,\n  A,\n  B;\n" + "InternalMass,\n  M,\n  LIGHT WALL,\n  BOTH,\n  12;\n")
    b = convert_idf(write(tmp_path, text))
    assert (b.component("M A").area, b.component("M A").inside.zone) == (12.0, "A")
    assert (b.component("M B").area, b.component("M B").inside.zone) == (12.0, "B")


# ---- constructions ------------------------------------------------------------------------
def test_ffactor_floor_is_energyplus_equivalent_construction(tmp_path):
    """F = 0.73 W/m/K, A = 48 m2, P = 28 m: R_eff = A / (P F) = 2.348 m2K/W; the fictitious layer
    is R_eff less 0.15 m of concrete (k 1.95) and the films 0.135 + 0.03 it includes."""
    F, A, P = 0.73, 48.0, 28.0
    text = (HEADER + f"Construction:FfactorGroundFloor,\n  SLAB F,\n  {F},\n  {A},\n  {P};\n"
            + "Site:GroundTemperature:FCfactorMethod,\n  " + ", ".join(["5"] * 6 + ["15"] * 6) + ";\n"
            + zone("Z") + box("Z", "Z", floor="GroundFCfactorMethod", floor_construction="SLAB F"))
    b = convert_idf(write(tmp_path, text))
    floor = b.component("Z F")
    R = sum(t / m.conductivity for m, t in floor.layers)
    R_fic = A / (P * F) - 0.15 / 1.95 - 0.135 - 0.03
    assert R == pytest.approx(R_fic + 0.15 / 1.95, rel=1e-9)
    concrete = floor.layers[0]  # inside first: the concrete faces the zone
    assert (concrete[1], concrete[0].density, concrete[0].specific_heat) == (0.15, 2240.0, 900.0)
    assert b.schedules[floor.outside.temperature].at(np.array([7]), np.array([1]), np.array([0]),
                                                     np.array([1.0]))[0] == 15.0


def test_ffactor_layer_is_energyplus_own():
    """EnergyPlus 25.2's eplusout.eio (Output:Constructions) for the 2019 small office prototype:
    the fictitious layer of F = 0.90012 W/m/K, A = 113.45 m2, P = 27.69 m is 4.31 m2K/W, and of
    A = 67.3 m2, P = 18.46 m 3.808 m2K/W."""
    assert E.ffactor_fictitious_resistance(0.90012, 113.45, 27.69) == pytest.approx(4.31, abs=5e-3)
    assert E.ffactor_fictitious_resistance(0.90012, 67.3, 18.46) == pytest.approx(3.808, abs=5e-4)


def test_cfactor_wall_is_energyplus_equivalent_construction():
    """C = 0.5 W/m2/K, 2 m deep: R_eff = 1/C + 0.0607 + 0.3479 x 2 (Engineering Reference's
    soil), the fictitious layer that less the concrete."""
    assert E.cfactor_fictitious_resistance(0.5, 2.0) == pytest.approx(2 + 0.0607 + 0.6958 - 0.15 / 1.95)
    assert E.ffactor_fictitious_resistance(0.73, 48.0, 0.0) == E.FC_NO_PERIMETER


def test_argon_gap_conducts_by_energyplus_coefficients():
    """A 6 mm gap is below convection's onset (Nu = 1 within 0.5 %): h = k/d + h_r with argon's
    k = 2.285e-3 + 5.149e-5 T, against air's 2.873e-3 + 7.76e-5 T, at 283.15 K."""
    T, d = 283.15, 0.006
    h_r = glazing.radiative_conductance(0.84, 0.84, T)
    for gas, (a, b) in (("argon", (2.285e-3, 5.149e-5)), ("krypton", (9.443e-4, 2.826e-5)),
                        ("air", (2.873e-3, 7.76e-5))):
        assert glazing.gap_conductance(d, 1.5, 0.84, 0.84, gas=gas) == pytest.approx((a + b * T) / d + h_r, rel=5e-3)
    half = glazing.gas_properties([("argon", 0.9), ("air", 0.1)], T)[0]
    assert half == pytest.approx(0.9 * (2.285e-3 + 5.149e-5 * T) + 0.1 * (2.873e-3 + 7.76e-5 * T))


def test_an_argon_window_converts_with_a_lower_gap_conductance(tmp_path):
    argon = TEXT.replace("  AIR GAP 13 MM,                !- Name\n  Air,", "  AIR GAP 13 MM,                !- Name\n  Argon,")
    assert argon != TEXT
    def gap(b):
        w = b.component("SOUTH WINDOW WEST")
        return min(m.conductivity / t for m, t in w.layers)
    assert gap(convert_idf(write(tmp_path, argon))) < gap(convert_idf(CASE600))


# ---- boundaries the file holds approximately ---------------------------------------------
def test_foundation_and_other_side_models_convert_and_are_listed(tmp_path):
    text = (HEADER + zone("Z") + box("Z", "Z", floor="Foundation", floor_object="KIVA")
            + "Foundation:Kiva,\n  KIVA;\n")
    b = convert_idf(write(tmp_path, text))
    assert b.component("Z F").outside.temperature == "ground temperature"
    assert any(line.startswith("BuildingSurface:Detailed Z F: outside boundary Foundation (Kiva) read as Ground")
               for line in b.data["not_modelled"])
    text = (HEADER + zone("Z") + box("Z", "Z", floor="OtherSideConditionsModel", floor_object="GAP")
            + "SurfaceProperty:OtherSideConditionsModel,\n  GAP,\n  GapConvectionRadiation;\n")
    b = convert_idf(write(tmp_path, text, "oscm.idf"))
    assert b.component("Z F").outside.solar_absorptance == 0.0
    assert any("OtherSideConditionsModel (gapconvectionradiation) read as outdoor air" in line
               for line in b.data["not_modelled"])


def test_a_constant_other_side_temperature_is_a_boundary(tmp_path):
    text = (HEADER + zone("Z") + box("Z", "Z", floor="OtherSideCoefficients", floor_object="AT 12")
            + "SurfaceProperty:OtherSideCoefficients,\n  AT 12,\n  4,\n  12,\n  1,\n  0,\n  0,\n  0,\n  0;\n")
    out = convert_idf(write(tmp_path, text)).component("Z F").outside
    assert (out.temperature, out.h) == (12.0, 4.0)


# ---- interzone pairs ------------------------------------------------------------------------
def swapped_pair():
    text = MULTIZONE.read_text()
    a = text.index("  BuildingSurface:Detailed,\n    WEST TO EAST")
    a_end = text.index("\n\n", a) + 2
    b = text.index("  BuildingSurface:Detailed,\n    EAST TO WEST")
    b_end = text.index("\n\n", b) + 2
    first, second = text[a:a_end], text[b:b_end]
    return text[:a] + second + text[a_end:b] + first + text[b_end:]


def test_an_interzone_pair_is_the_same_building_whatever_its_order(tmp_path):
    before = convert_idf(MULTIZONE)
    after = convert_idf(write(tmp_path, swapped_pair()))
    key = lambda b: sorted((c.name, c.inside.zone, getattr(c.outside, "zone", None), round(c.area, 6), c.layers,
                            tuple(sorted(c.solar_distribution))) for c in b.components)  # noqa: E731
    assert key(before) == key(after)
    p = after.component("WEST TO EAST")
    assert (p.inside.zone, p.outside.zone) == ("WEST OFFICE", "EAST OFFICE")


def test_each_face_of_a_partition_takes_its_own_zones_sun():
    """EAST OFFICE's window lights the partition's face in EAST OFFICE, its outer face: the share
    of its area times its absorptance, of the direct sun and of the diffuse, and the network puts
    each on that face's node."""
    from nodeforce.model.network import assemble, input_names
    b = convert_idf(MULTIZONE)
    w = b.component("EAST SOUTH WINDOW")
    net = assemble(b)
    p = b.component("WEST TO EAST")
    for sun, shares in w.sun_inputs:
        shares = dict(shares)
        assert shares.get("WEST TO EAST", 0.0) > 0
        j = input_names(b).index(sun)
        assert net.B[p.node_ids[-1] - 1, j] == pytest.approx(w.solar_transmittance * w.area * shares["WEST TO EAST"])
        assert net.B[p.node_ids[0] - 1, j] == 0.0


def test_wall_interzone_may_name_the_zone_beyond(tmp_path):
    text = (HEADER + zone("A") + box("A", "A") + zone("B", x=20) + box("B", "B")
            + "Wall:Interzone,\n  TO B,\n  LIGHT WALL,\n  A,\n  B,\n  90,\n  90,\n  4,\n  0,\n  0,\n  3,\n  2;\n")
    p = convert_idf(write(tmp_path, text)).component("TO B")
    assert (p.inside.zone, p.outside.zone, p.area) == ("A", "B", 6.0)


# ---- spectral pane data -------------------------------------------------------------------
def test_solar_average_of_spectral_data():
    """A flat spectrum averages to itself; a pane clear below 0.7 um and opaque above lets through
    the share of the solar spectrum's energy below 0.7 um (ASTM E891's direct AM1.5, read here by
    the trapezoid rule on its own table)."""
    assert glazing.solar_average([0.3, 2.5], [0.8, 0.8]) == pytest.approx(0.8)
    lam, E = glazing.solar_spectrum()
    assert lam[0] == 0.3 and E[1] == 3.4  # the standard's first rows
    k = int(np.searchsorted(lam, 0.7))  # clear up to the standard's wavelength k, opaque from k + 1
    full = lam <= 2.5
    share = (np.trapezoid(E[:k + 1], lam[:k + 1]) + 0.5 * (lam[k + 1] - lam[k]) * E[k]) / np.trapezoid(E[full], lam[full])
    step = glazing.solar_average([0.3, lam[k], lam[k + 1], 2.5], [1.0, 1.0, 0.0, 0.0])
    assert step == pytest.approx(share, rel=1e-9)
    assert 0.3 < share < 0.5  # about 40 % of the sun's energy is below 0.7 um


def test_a_flat_spectral_pane_is_its_spectral_average(tmp_path):
    """Case 600's pane given as spectral data flat at its averages converts to the same window."""
    spectral = TEXT.replace("  SpectralAverage,              !- Optical Data Type\n  ,",
                            "  Spectral,                     !- Optical Data Type\n  FLAT,")
    assert spectral != TEXT
    spectral += ("MaterialProperty:GlazingSpectralData,\n  FLAT,\n"
                 + ",\n".join(f"  {lam}, 0.86156, 0.07846, 0.07846" for lam in (0.3, 0.8, 1.5, 2.5)) + ";\n")
    w, w0 = (convert_idf(p).component("SOUTH WINDOW WEST") for p in (write(tmp_path, spectral), CASE600))
    assert w.solar_transmittance == pytest.approx(w0.solar_transmittance, abs=1e-6)
    assert w.outside.solar_absorptance == pytest.approx(w0.outside.solar_absorptance, abs=1e-6)


def test_daylight_saving_is_said(tmp_path):
    text = TEXT + "RunPeriodControl:DaylightSavingTime,\n  2nd Sunday in March,\n  1st Sunday in November;\n"
    b = convert_idf(write(tmp_path, text))
    assert "RunPeriodControl:DaylightSavingTime: not applied; the schedules run on standard time all year" in \
        b.data["not_modelled"]


def test_an_infiltrations_wind_and_temperature_terms_are_followed(tmp_path):
    """0.5 air changes times 0.1 + 0.01 |dT| + 0.224 v (the 2019 prototypes' form, their constant
    term 0): the file declares the design flow, the terms and the wind at the zone's surfaces' mean
    height (1.35 m in case 600's Country terrain) over the station's, and says nothing of them."""
    from nodeforce.model import convection
    text = TEXT.replace("  1,                            !- Constant Term Coefficient\n"
                        "  0,                            !- Temperature Term Coefficient\n"
                        "  0,                            !- Velocity Term Coefficient",
                        "  0.1,\n  0.01,\n  0.224,")
    assert text != TEXT
    b = convert_idf(write(tmp_path, text))
    z = b.zones[0]
    (v,) = z.ventilation
    assert (z.air_change_rate, v.schedule, v.controls) == (0.0, None, None)
    assert v.flow == pytest.approx(0.5 * z.volume, rel=1e-9)
    assert v.terms == (0.1, 0.01, 0.224, 0.0)
    assert v.wind_factor == pytest.approx((270 / 10) ** 0.14 * (1.35 / 270) ** 0.14, rel=1e-5)
    assert v.wind_factor == pytest.approx(convection.wind_at_height(1.0, 1.35, "country"), rel=1e-5)
    assert not any("INFILTRATION" in line for line in b.data["not_modelled"])


def test_a_ventilation_s_controls_are_held(tmp_path):
    """A 2019 warehouse's exhaust: 37.76 m3/s that runs above 29.44 C indoors, its other limits at
    EnergyPlus's defaults; a limit by schedule is said not held."""
    vent = ("ZoneVentilation:DesignFlowRate,\n  EXHAUST,\n  CASE 600 ZONE,\n  CONTINUOUS,\n  Flow/Zone,\n"
            "  37.76,\n  ,\n  ,\n  ,\n  Exhaust,\n  31.1,\n  0.51,\n  1,\n  0,\n  0,\n  0,\n  29.44,\n  ,\n"
            "  100,\n  ,\n  -100,\n  ,\n  -100,\n  ,\n  100,\n  {},\n  40;\n")
    b = convert_idf(write(tmp_path, TEXT + vent.format("")))
    (v,) = b.zones[0].ventilation
    assert v.flow == pytest.approx(37.76 * 3600)
    assert (v.terms, v.controls) == (None, (29.44, 100.0, -100.0, -100.0, 100.0, 40.0))
    assert b.zones[0].air_change_rate == pytest.approx(0.5)  # the infiltration stays constant
    assert not any("EXHAUST" in line for line in b.data["not_modelled"])
    b = convert_idf(write(tmp_path, TEXT + vent.format("CONTINUOUS")))
    assert any(line.startswith("ZoneVentilation:DesignFlowRate EXHAUST: its control schedules (Maximum Outdoor "
                               "Temperature Schedule Name) not held") for line in b.data["not_modelled"])


def test_a_lights_return_air_fraction_leaves_with_the_return_air(tmp_path):
    """480 W of lights, 0.4 to the return air, 0.4 radiant and 0.2 visible: the zone gets 0.6 of
    it, (0.4 + 0.2) / 0.6 of that radiant; EnergyPlus free-floating gives the return air's share
    to no zone (its 2004 medium office's mid core: 28.4 C, and 30.1 C with the fraction 0)."""
    text = (HEADER + zone("Z") + box("Z", "Z")
            + "Lights,\n  L,\n  Z,\n  CONTINUOUS,\n  LightingLevel,\n  480,\n  ,\n  ,\n  0.4,\n  0.4,\n  0.2,\n  1;\n")
    (g,) = convert_idf(write(tmp_path, text)).zone("Z").gains
    assert (g.power, g.radiant_fraction) == pytest.approx((0.6 * 480, 1.0))


def test_simple_glazing_absorbs_as_energyplus_layer_and_keeps_its_shgc(tmp_path):
    """U 2.0441736, SHGC 0.38 (the 2019 small office's windows): T = 0.2937 (EnergyPlus's eio:
    0.295); step 4's films R_o,s = 1/(2.225824 x + 20.57708) = 0.04815 and R_i,s = 0.1229 at
    x = SHGC - T = 0.0863, the layer R_l = 1/U - 0.13876 - 0.03423 = 0.3163, Fr_in = (R_o,s + R_l/2) /
    (R_o,s + R_l + R_i,s) = 0.4233, so the layer absorbs 0.0863 / 0.4233 = 0.204 of the sun. The
    converted window holds it half at each face of its layer, as EnergyPlus's window heat balance
    splits a glass layer's short-wave; between those films the outer face's half then flows in by
    R_o,s / (R_o,s + R_l + R_i,s) and the inner face's by (R_o,s + R_l) / (R_o,s + R_l + R_i,s), on
    average Fr_in: T + the inward-flowing absorbed sun = SHGC."""
    assert glazing.simple_glazing_absorptance(2.0441736, 0.38) == pytest.approx(0.0863 / 0.4233, rel=2e-3)
    text = TEXT.replace("  DOUBLE CLEAR,                 !- Name\n", "  DOUBLE CLEAR,\n  SIMPLE;\nConstruction,\n  UNUSED,\n", 1)
    text += "WindowMaterial:SimpleGlazingSystem,\n  SIMPLE,\n  2.0441736,\n  0.38;\n"
    w = convert_idf(write(tmp_path, text)).component("SOUTH WINDOW WEST")
    a_out, a_in = w.outside.solar_absorptance, w.inner_solar_absorptance
    assert a_out == pytest.approx(a_in, abs=1e-6)
    assert a_out + a_in == pytest.approx(glazing.simple_glazing_absorptance(2.0441736, 0.38), abs=1e-6)
    R_l = sum(t / m.conductivity for m, t in w.layers)
    assert R_l == pytest.approx(0.3163, abs=2e-4)
    R_os, R_is = 0.04815, 0.1229
    inward = (a_out * R_os + a_in * (R_os + R_l)) / (R_os + R_l + R_is)
    assert w.solar_transmittance + inward == pytest.approx(0.38, abs=2e-3)


# the simple glazing's angular curves at 60 deg (cos 0.5), summed by hand from the Engineering
# Reference's coefficients: c1/2 + c2/4 + c3/8 + c4/16 (no constant term: 0 at 90 deg)
E60 = 1.51 / 2 + 2.49 / 4 - 5.87 / 8 + 2.88 / 16  # 0.82375
J60 = 0.08 / 2 + 6.02 / 4 - 8.84 / 8 + 3.74 / 16  # 0.67375
A60 = 3.36 / 2 - 3.85 / 4 + 1.49 / 8 + 0.01 / 16  # 0.904375
B60 = 2.83 / 2 - 2.42 / 4 + 0.04 / 8 + 0.55 / 16  # 0.849375
C60 = 2.45 / 2 - 1.58 / 4 - 0.64 / 8 + 0.77 / 16  # 0.798125
D60 = 2.85 / 2 - 2.58 / 4 + 0.40 / 8 + 0.35 / 16  # 0.851875
F60 = 1.21 / 2 + 3.14 / 4 - 6.37 / 8 + 3.03 / 16  # 0.783125
G60 = 1.09 / 2 + 3.54 / 4 - 6.84 / 8 + 3.23 / 16  # 0.776875
H60 = 0.98 / 2 + 3.83 / 4 - 7.13 / 8 + 3.33 / 16  # 0.764375
I60 = 0.79 / 2 + 3.93 / 4 - 6.86 / 8 + 3.15 / 16  # 0.716875


@pytest.mark.parametrize("U, shgc, at_60", [
    (1.0, 0.6, E60),  # region E: low U, high SHGC
    (1.0, 0.2, J60),  # J: low U, low SHGC
    (2.5, 0.4, (F60 + G60 + H60 + I60) / 4),  # F, G, H, I averaged
    (2.5, 0.2, (F60 + H60) / 2),  # F and H
    (5.0, 0.7, A60),  # A: single clear
    (5.0, 0.5, (B60 + D60 + C60 + D60) / 4),  # B, C, D (D twice, as EnergyPlus averages them)
    (5.0, 0.2, D60),  # D
    (1.0, 0.4, (E60 + J60) / 2),  # halfway between E and J in SHGC
    ((3.4068 + 4.5424) / 2, 0.7, (E60 + A60) / 2),  # halfway between E and A in U
])
def test_simple_glazing_angular_transmittance_by_region(U, shgc, at_60):
    """EnergyPlus's simple glazing: T(angle) / T(0) the curve of the (U, SHGC) region, 1 at
    normal incidence, 0 at grazing incidence."""
    f = glazing.simple_glazing_factors(U, shgc, np.array([0.0, 60.0, 90.0]))
    assert f == pytest.approx([1.0, at_60, 0.0], abs=1e-9)


# ... and the reflectance curves' polynomials at 60 deg, 1 + c1/2 + c2/4 + c3/8 + c4/16, from which
# EnergyPlus takes the transmittance curve of the same letter
RF60 = 1 - 3.15 / 2 + 10.98 / 4 - 13.14 / 8 + 5.32 / 16  # 0.86
RG60 = 1 - 3.25 / 2 + 11.32 / 4 - 13.54 / 8 + 5.49 / 16  # 0.855625
RH60 = 1 - 3.39 / 2 + 11.70 / 4 - 13.94 / 8 + 5.64 / 16  # 0.84
RI60 = 1 - 4.06 / 2 + 13.55 / 4 - 15.74 / 8 + 6.27 / 16  # 0.781875


def test_simple_glazing_absorbs_at_the_angle_energyplus_gives_its_layer():
    """EnergyPlus's simple glazing layer at 60 deg (U 2.16, SHGC 0.37: region F, G, H, I): T = T0
    f_T, R = R0 (1 - r) + r with r the reflectance curve less the transmittance curve, and the
    absorptance 1 - T - R, above its normal value (0.238 against 0.206); 0 of it neither at
    normal incidence nor beyond, and at grazing incidence all is reflected."""
    U, shgc = 2.1577388, 0.37
    T0, a0 = glazing.simple_glazing_transmittance(U, shgc), glazing.simple_glazing_absorptance(U, shgc)
    f = (F60 + G60 + H60 + I60) / 4
    r = (RF60 + RG60 + RH60 + RI60) / 4 - f
    T, R = T0 * f, (1 - T0 - a0) * (1 - r) + r
    a = glazing.simple_glazing_angular_absorptance(U, shgc, np.array([0.0, 60.0, 90.0]))
    assert a[:2] == pytest.approx([a0, 1 - T - R], abs=1e-9)
    assert a[1] == pytest.approx(0.238, abs=1e-3) and a0 == pytest.approx(0.206, abs=1e-3)
    assert a[2] == pytest.approx(0.0001, abs=1e-9)  # R held at 0.9999 - T, T 0


def test_simple_glazing_writes_its_angular_table(tmp_path):
    """The converted simple glazing (U 2.0441736, SHGC 0.38: region F, G, H, I) carries the
    curve every 10 deg, its diffuse factor the table's hemispherical mean: below 1, above the
    factor at 60 deg."""
    text = TEXT.replace("  DOUBLE CLEAR,                 !- Name\n", "  DOUBLE CLEAR,\n  SIMPLE;\nConstruction,\n  UNUSED,\n", 1)
    text += "WindowMaterial:SimpleGlazingSystem,\n  SIMPLE,\n  2.0441736,\n  0.38;\n"
    a = convert_idf(write(tmp_path, text)).component("SOUTH WINDOW WEST").angular
    assert a.angles[6] == 60 and a.factors[6] == pytest.approx((F60 + G60 + H60 + I60) / 4, abs=1e-9)
    assert a.factors[0] == 1.0 and a.factors[-1] == pytest.approx(0.0, abs=1e-12)
    assert a.factors[6] < a.diffuse < 1.0
    g = convert_idf(write(tmp_path, text)).component("SOUTH WINDOW WEST").angular_absorptance
    alpha = glazing.simple_glazing_absorptance(2.0441736, 0.38)
    assert g.table("outside")[1][6] * alpha == pytest.approx(
        float(glazing.simple_glazing_angular_absorptance(2.0441736, 0.38, 60.0)), abs=1e-5)


# ---- gains ---------------------------------------------------------------------------------
def test_a_negative_other_equipment_removes_heat(tmp_path):
    """EnergyPlus's IDD sets no minimum on OtherEquipment's levels: a negative one removes heat
    (its convective and radiant parts, level x (1 - latent - lost)). Other gains stay >= 0."""
    floor = 8.0 * 6.0
    other = ("OtherEquipment,\n  Sink,\n  None,\n  Z,\n  ON,\n  Watts/Area,\n  ,\n  -2,\n  ,\n  0,\n  0.3,\n  0.25;\n"
             "OtherEquipment,\n  Source,\n  None,\n  Z,\n  ON,\n  EquipmentLevel,\n  352,\n  ,\n  ,\n  0,\n  0,\n  0;\n"
             "Schedule:Constant,\n  ON,\n  ,\n  1;\n")
    b = convert_idf(write(tmp_path, HEADER + zone("Z") + box("Z", "Z") + other))
    gains = {g["name"]: g for g in b.data["zones"][0]["gains"]}
    assert gains["Sink"]["power"] == pytest.approx(-2 * floor * (1 - 0.25))
    assert gains["Sink"]["radiant_fraction"] == pytest.approx(0.3 / 0.75)
    assert gains["Source"]["power"] == pytest.approx(352.0)
    electric = "ElectricEquipment,\n  Sink,\n  Z,\n  ON,\n  EquipmentLevel,\n  -50,\n  ,\n  ,\n  0,\n  0,\n  0;\n"
    with pytest.raises(InputError, match="Design Level: -50 must be >= 0"):
        convert_idf(write(tmp_path, HEADER + zone("Z") + box("Z", "Z") + electric + "Schedule:Constant,\n  ON,\n  ,\n  1;\n"))


@pytest.mark.parametrize("old", ["8.4", "8.6"])
def test_an_other_equipment_of_an_8_x_file_gains_its_fuel_type_field(tmp_path, old):
    """A file of 8.4 to 8.8 is read against 8.9's IDD, which inserted OtherEquipment's Fuel Type
    after its name: the 8.4 or 8.6 object (name, zone, schedule, method, level, ...) still gives its
    zone 352 W, with a radiant fraction of 0.2 of the 0.8 not lost (0.25)."""
    version = HEADER[HEADER.index("Version"):HEADER.index(";", HEADER.index("Version")) + 1]
    other = ("OtherEquipment,\n  Test 352a,  !- Name\n  Z,  !- Zone Name\n  ON,\n  EquipmentLevel,\n  440,\n  ,\n  ,\n"
             "  0,\n  0.2,\n  0.2;\n" "Schedule:Constant,\n  ON,\n  ,\n  1;\n")
    b = convert_idf(write(tmp_path, HEADER.replace(version, f"Version, {old};") + zone("Z") + box("Z", "Z") + other))
    (gain,) = b.data["zones"][0]["gains"]
    assert (gain["name"], gain["power"], gain["radiant_fraction"]) == ("Test 352a", pytest.approx(352.0), pytest.approx(0.25))
    assert E.to_schema_min("OtherEquipment,A,Z,S;") == "OtherEquipment,A, None,Z,S;"


# ---- a window from a WINDOW data file -------------------------------------------------------
def window5(gas):
    """A WINDOW 5 data file of case 600's double glazing: its panes (3.175 mm, 1.06 W/m/K, T 0.86156,
    R 0.07846, emissivity 0.84) and 13 mm gap of a gas given by coefficients as the file writes them:
    conductivity W/m/K, viscosity g/m/s, specific heat kJ/kg/K."""
    (k, mu, cp, M) = gas
    coefficients = " ".join(f"{v:.9g}" for v in (*k, *(1e3 * v for v in mu), *(1e-3 * v for v in cp)))
    pane = "3.175 1.06 0.86156 0.07846 0.07846 0.91325 0.082 0.082 0.00 0.84 0.84 CLEAR.DAT"
    return ("Window5 Data File for EnergyPlus\nWindow name      : DOUBLE CLEAR\n# Glazing Systems: 1\n"
            "GLAZING SYSTEM DATA: Height Width nPanes Uval-center SC-center SHGC-center Tvis-center\n"
            " System1         :   2000   3000      2      2.9      0.88      0.76       0.81\n"
            "GLASS DATA       : Layer#  Thickness  Cond Tsol Rfsol Rbsol Tvis Rfvis Rbvis  Tir  EmissF  EmissB  File\n"
            f" System1         :   1   {pane}\n                     2   {pane}\n"
            "GAP DATA         : Gap# Thick nGasses\n System1         :   1  13.0    1\n"
            "GAS DATA         : GasName Fraction MolWeight ACond BCond CCond AVisc BVisc CVisc ASpHeat BSpHeat CSpHeat\n"
            f" System1 Gap1    : Air 1.0000 {M} {coefficients}\n")


def test_a_window_data_file_is_its_panes_and_gaps(tmp_path):
    """Construction:WindowDataFile is built as EnergyPlus builds it, from the file's glass and gap
    rows: with case 600's panes and EnergyPlus's air coefficients in the file's units, the window
    is case 600's layer for layer; a missing file is refused in one line."""
    layered = 'Construction,\n  DOUBLE CLEAR,                 !- Name\n  CLEAR PANE 3.175 MM,          !- Outside Layer\n' \
              '  AIR GAP 13 MM,                !- Layer 2\n  CLEAR PANE 3.175 MM;          !- Layer 3\n'
    assert layered in TEXT
    (tmp_path / "data").mkdir()
    (tmp_path / "data" / "W5.dat").write_text(window5(glazing.GASES["air"]))
    text = TEXT.replace(layered, "Construction:WindowDataFile,\n  DOUBLE CLEAR,\n  ..\\data\\W5.dat;\n")
    (tmp_path / "run").mkdir()
    b = convert_idf(write(tmp_path / "run", text))
    own, reference = b.component("SOUTH WINDOW WEST"), convert_idf(CASE600).component("SOUTH WINDOW WEST")
    assert [t for _, t in own.layers] == pytest.approx([t for _, t in reference.layers])
    assert [m.conductivity for m, _ in own.layers] == pytest.approx([m.conductivity for m, _ in reference.layers], rel=1e-9)
    assert own.solar_transmittance == pytest.approx(reference.solar_transmittance)
    assert own.inner_solar_absorptance == pytest.approx(reference.inner_solar_absorptance)
    assert any(line.startswith("Construction:WindowDataFile DOUBLE CLEAR: its panes and gaps read from W5.dat")
               for line in b.data["not_modelled"])
    with pytest.raises(InputError, match=r"File Name: '..\\\\data\\\\W5.dat' is not found beside the IDF"):
        convert_idf(write(tmp_path, text))


def test_a_parametric_vertex_is_refused_naming_its_field_and_the_preprocessor(tmp_path):
    """EnergyPlus runs a file with `=$height` in a vertex only after its ParametricPreprocessor has
    expanded it: the refusal names the coordinate that holds the expression."""
    text = HEADER + zone("Z") + box("Z", "Z").replace("0, 0, 2.7,\n  0, 0, 0,", "0, 0, =$height,\n  0, 0, 0,", 1)
    with pytest.raises(InputError, match=r"'Z S', field Vertex 1 Z-coordinate: '=\$height' is a parametric "
                                         r"expression: expand the file with EnergyPlus's ParametricPreprocessor"):
        convert_idf(write(tmp_path, text))


def box_24(multiplier=""):
    """A 4 x 4 x 3 m box of EnergyPlus 24.1 with a 2 m2 south window of U 2, SHGC 0.6, and the
    given SurfaceProperty:IncidentSolarMultiplier text."""
    walls = {"S": [(0, 0, 3), (0, 0, 0), (4, 0, 0), (4, 0, 3)], "E": [(4, 0, 3), (4, 0, 0), (4, 4, 0), (4, 4, 3)],
             "N": [(4, 4, 3), (4, 4, 0), (0, 4, 0), (0, 4, 3)], "W": [(0, 4, 3), (0, 4, 0), (0, 0, 0), (0, 0, 3)],
             "F": [(4, 4, 0), (4, 0, 0), (0, 0, 0), (0, 4, 0)], "R": [(0, 4, 3), (0, 0, 3), (4, 0, 3), (4, 4, 3)]}
    kinds = {"F": "Floor", "R": "Roof"}
    text = ("Version, 24.1;\nSite:Location, Site, 40, -105, -7, 1600;\n"
            "GlobalGeometryRules, UpperLeftCorner, CounterClockWise, World;\n"
            "Material:NoMass, R2, Rough, 2.0, 0.9, 0.6, 0.6;\nConstruction, OPAQUE, R2;\n"
            "WindowMaterial:SimpleGlazingSystem, SGS, 2.0, 0.6;\nConstruction, GLAZING, SGS;\n"
            "Zone, Z, 0, 0, 0, 0, 1, 1, autocalculate, autocalculate;\n")
    for key, points in walls.items():
        flat = ", ".join(f"{x}, {y}, {z}" for x, y, z in points)
        text += (f"BuildingSurface:Detailed, {key}, {kinds.get(key, 'Wall')}, OPAQUE, Z, , Outdoors, , SunExposed, "
                 f"WindExposed, autocalculate, 4, {flat};\n")
    text += "FenestrationSurface:Detailed, WIN, Window, GLAZING, S, , autocalculate, , 1, 4, 1, 0, 2, 1, 0, 1, 3, 0, 1, 3, 0, 2;\n"
    return text + multiplier


def test_a_constant_incident_solar_multiplier_scales_the_windows_sun(tmp_path):
    """EnergyPlus multiplies the sun incident on the window by the multiplier times its schedule
    (0.5 x 0.8 = 0.4): what it transmits and what its glazing absorbs, outside and inside, scale
    by 0.4. A varying schedule is listed, not held."""
    plain = convert_idf(write(tmp_path, box_24(), "plain.idf")).component("WIN")
    scaled = convert_idf(write(tmp_path, box_24("SurfaceProperty:IncidentSolarMultiplier, WIN, 0.5, HALF;\n"
                                                "Schedule:Constant, HALF, , 0.8;\n"), "scaled.idf")).component("WIN")
    assert scaled.solar_transmittance == pytest.approx(0.4 * plain.solar_transmittance, abs=1e-6)
    assert scaled.inner_solar_absorptance == pytest.approx(0.4 * plain.inner_solar_absorptance, abs=1e-6)
    assert scaled.outside.solar_absorptance == pytest.approx(0.4 * plain.outside.solar_absorptance)
    varying = box_24("SurfaceProperty:IncidentSolarMultiplier, WIN, 1, DAY;\n"
                     "Schedule:Compact, DAY, , Through: 12/31, For: AllDays, Until: 12:00, 1, Until: 24:00, 0.5;\n")
    b = convert_idf(write(tmp_path, varying, "varying.idf"))
    assert b.component("WIN").solar_transmittance == pytest.approx(plain.solar_transmittance)
    assert any(line.startswith("SurfaceProperty:IncidentSolarMultiplier WIN: its schedule 'DAY' varies")
               for line in b.data["not_modelled"])


# ---- shading surfaces ----------------------------------------------------------------------
def test_a_projection_overhang_and_fins_are_the_polygons_written_by_hand(tmp_path):
    """Case 610's overhang (1 m deep along the 8 m south wall at the roof's 2.7 m) as a
    Shading:Overhang:Projection over the west window (3 x 2 m, sill 0.2 m, 0.5 m from the west
    wall): 0.5 m above its head, 0.5 m beyond its left edge and 4.5 m beyond its right, depth 0.5 of
    its height; and its fins (0.1 m beyond each edge, 0.2 m over the head, 0.1 m under the sill,
    0.2 of its width deep), against the same surfaces written as Shading:Zone:Detailed."""
    projected = ("Shading:Overhang:Projection,\n  OVERHANG,\n  SOUTH WINDOW WEST,\n  0.5,\n  90,\n  0.5,\n  4.5,\n"
                 "  0.5;\n"
                 "Shading:Fin:Projection,\n  FIN,\n  SOUTH WINDOW WEST,\n  0.1,\n  0.2,\n  0.1,\n  90,\n  0.2,\n"
                 "  0.1,\n  0.2,\n  0.1,\n  90,\n  0.2;\n")

    def detailed(name, points):
        return (f"Shading:Zone:Detailed,\n  {name},\n  SOUTH WALL,\n  ,\n  {len(points)},\n  "
                + ",\n  ".join(f"{x}, {y}, {z}" for x, y, z in points) + ";\n")
    by_hand = (detailed("OVERHANG", [(0, -1, 2.7), (0, 0, 2.7), (8, 0, 2.7), (8, -1, 2.7)])
               + detailed("FIN Left", [(0.4, 0, 2.4), (0.4, 0, 0.1), (0.4, -0.6, 0.1), (0.4, -0.6, 2.4)])
               + detailed("FIN Right", [(3.6, 0, 2.4), (3.6, 0, 0.1), (3.6, -0.6, 0.1), (3.6, -0.6, 2.4)]))
    a, b = (convert_idf(write(tmp_path, TEXT + extra, f"{k}.idf")) for k, extra in enumerate((projected, by_hand)))
    assert [s.name for s in a.shading] == [s.name for s in b.shading] == ["OVERHANG", "FIN Left", "FIN Right"]
    for s, t in zip(a.shading, b.shading):
        assert np.allclose(s.vertices, t.vertices, atol=1e-9) and s.faces == t.faces
    # the overhang over the whole south wall; each fin stands in front of the south wall alone
    assert a.shading[0].faces == ("SOUTH WALL", "SOUTH WINDOW WEST", "SOUTH WINDOW EAST")
    assert a.shading[1].faces == ("SOUTH WALL", "SOUTH WINDOW WEST", "SOUTH WINDOW EAST")
    wall = a.component("SOUTH WALL")
    assert len(wall.holes) == 2 and wall.vertices[1] == (0.0, 0.0, 0.0)
    assert not any(line.startswith("Shading:") for line in a.data["not_modelled"])


def test_a_shaded_face_sees_less_sky_for_its_long_wave_exchange(tmp_path):
    """EnergyPlus scales a face's sky view for long-wave exchange by its diffuse shading ratio."""
    from nodeforce.model.shading import sky_diffuse_ratio
    overhang = ("Shading:Building:Detailed,\n  OVERHANG,\n  ,\n  4,\n  0, -1, 2.7,\n  0, 0, 2.7,\n  8, 0, 2.7,\n"
                "  8, -1, 2.7;\n")
    shaded, plain = (convert_idf(write(tmp_path, TEXT + extra, f"{k}.idf")) for k, extra in enumerate((overhang, "")))
    window, window0 = shaded.component("SOUTH WINDOW WEST"), plain.component("SOUTH WINDOW WEST")
    ratio = sky_diffuse_ratio(window.vertices, np.array([0.0, -1.0, 0.0]), [shaded.shading[0].vertices])
    assert 0.5 < ratio < 1.0
    assert window.outside.sky_view_factor == pytest.approx(window0.outside.sky_view_factor * ratio, abs=1e-6)
    assert shaded.component("NORTH WALL").outside == plain.component("NORTH WALL").outside


def test_minimal_shadowing_casts_no_shadow(tmp_path):
    """EnergyPlus's MinimalShadowing solar distribution shades no exterior face: nor does the file."""
    overhang = ("Shading:Building:Detailed,\n  OVERHANG,\n  ,\n  4,\n  0, -1, 2.7,\n  0, 0, 2.7,\n  8, 0, 2.7,\n"
                "  8, -1, 2.7;\n")
    text = TEXT.replace("FullInteriorAndExterior,      !- Solar Distribution", "MinimalShadowing,  !- Solar Distribution")
    b = convert_idf(write(tmp_path, text + overhang))
    assert b.shading == () and all(c.vertices is None for c in b.components)
    assert "MinimalShadowing" in b.data["description"]
    assert not any("OVERHANG" in line for line in b.data["not_modelled"])


def test_the_building_shades_itself_where_two_faces_stand_in_front_of_each_other(tmp_path):
    """Two boxes 2 m apart, A (8 x 6 m) west of B (6 x 12 m), both 2.7 m high: A's east wall and B's
    west wall face each other and shade each other (EnergyPlus's self-shading), as A's north wall
    and B's west wall north of it do; a box's own walls and roof stand behind one another's planes
    and shade nothing. With the sun due east at an
    altitude a, B's west wall leaves A's east wall sunlit from 2.7 - 2 tan(a) up."""
    from nodeforce.model.shading import sunlit_fraction
    text = HEADER + zone("A") + box("A", "A") + zone("B", x=10.0) + box("B", "B", L=6.0, W=12.0)
    b = convert_idf(write(tmp_path, text))
    casts = {s.name: s.faces for s in b.shading}
    assert casts == {"A E": ("B W",), "A N": ("B W",), "B W": ("A E", "A N")}
    wall = b.component("A E")
    a = np.radians(30.0)
    sun = np.array([[np.cos(a), 0.0, np.sin(a)]])
    expected = 2.0 * np.tan(a) / 2.7
    assert sunlit_fraction(wall.vertices, np.array([1.0, 0.0, 0.0]), b.shades_of("A E"), sun)[0] == \
        pytest.approx(expected, abs=1e-9)
    assert convert_idf(CASE600).shading == ()


# ---- internal gains -----------------------------------------------------------------------
def test_a_persons_sensible_heat_is_energyplus_polynomial():
    """The Engineering Reference's polynomial at 120 W and 23 C, by hand:
    120.457227 (1, M, M^2 terms) + 23 x 0.45282168 - 23^2 x 0.107280448 = 74.1208 W;
    its slope at 24 C, 0.45282168 - 2 x 24 x 0.107280448 = -4.69664 W/K, against a central
    difference; a 10 W activity bounded at 10 W, as EnergyPlus bounds it, with no slope."""
    from nodeforce.model.gains import people_sensible_heat, people_sensible_slope
    assert people_sensible_heat(120.0, 23.0) == pytest.approx(74.1208, abs=1e-4)
    assert people_sensible_slope(120.0, 24.0) == pytest.approx(-4.69664, abs=1e-5)
    assert people_sensible_slope(120.0, 24.0) == pytest.approx(
        (people_sensible_heat(120.0, 24.01) - people_sensible_heat(120.0, 23.99)) / 0.02, rel=1e-6)
    assert (people_sensible_heat(10.0, 24.0), people_sensible_slope(10.0, 24.0)) == (10.0, 0.0)


def test_a_zones_gains_as_energyplus_splits_them(tmp_path):
    """An 8 x 6 m zone: 0.1 person/m2 at 120 W (4.8 people, sensible heat by the polynomial),
    10 W/m2 of lights of which 0.2 goes to the return air, 500 W of equipment 0.1 latent and
    0.2 lost. By hand, with the air at T: people 4.8 (69.5314 - 4.69664 (T - 24)) W, radiant
    0.3 of 69.5314; lights 480 x 0.8 = 384 W, (0.4 + 0.2) / 0.8 = 0.75 of it radiant;
    equipment 500 x 0.7 = 350 W, 0.3 / 0.7 of it radiant: 1067.75 W at 24 C."""
    text = (HEADER + zone("Z") + box("Z", "Z") + "Schedule:Constant,\n  ACTIVITY,\n  ,\n  120;\n"
            + "People,\n  P,\n  Z,\n  ,\n  People/Area,\n  ,\n  0.1,\n  ,\n  0.3,\n  autocalculate,\n  ACTIVITY;\n"
            + "Lights,\n  L,\n  Z,\n  ,\n  Watts/Area,\n  ,\n  10,\n  ,\n  0.2,\n  0.4,\n  0.2,\n  1;\n"
            + "ElectricEquipment,\n  E,\n  Z,\n  ,\n  EquipmentLevel,\n  500,\n  ,\n  ,\n  0.1,\n  0.3,\n  0.2;\n")
    gains = {g.name: g for g in convert_idf(write(tmp_path, text)).zone("Z").gains}
    people, lights, equipment = gains["P"], gains["L"], gains["E"]
    assert people.power == pytest.approx(4.8 * 69.5314, abs=1e-3) and people.radiant_fraction == 0.3
    assert (people.temperature_slope, people.reference_temperature) == (pytest.approx(4.8 * -4.69664), 24.0)
    assert (lights.power, lights.radiant_fraction) == pytest.approx((384.0, 0.75))
    assert (equipment.power, equipment.radiant_fraction) == pytest.approx((350.0, 0.3 / 0.7))
    assert people.power + lights.power + equipment.power == pytest.approx(1067.75, abs=1e-2)
    assert not lights.temperature_slope and not equipment.temperature_slope


def test_a_level_per_person_takes_the_zones_people(tmp_path):
    """EnergyPlus multiplies a Watts/Person level by the zone's occupants, its People's numbers:
    two People objects in the 8 x 6 m zone, 3 people and one per 12 m2 (4), so 7 people; lights
    at 20 W a person give 140 W, 0.5 of it to the return air: 70 W."""
    people = "People,\n  {},\n  Z,\n  ,\n  {},\n  {},\n  ,\n  {},\n  0.3,\n  0.6,\n  ACTIVITY;\n"
    text = (HEADER + zone("Z") + box("Z", "Z") + "Schedule:Constant,\n  ACTIVITY,\n  ,\n  120;\n"
            + people.format("P1", "People", 3, "") + people.format("P2", "Area/Person", "", 12)
            + "Lights,\n  L,\n  Z,\n  ,\n  Watts/Person,\n  ,\n  ,\n  20,\n  0.5,\n  0.4,\n  0.1,\n  1;\n")
    gains = {g.name: g for g in convert_idf(write(tmp_path, text)).zone("Z").gains}
    assert gains["L"].power == pytest.approx(70.0)
    assert gains["P1"].power + gains["P2"].power == pytest.approx(7 * 120 * 0.6)


# ---- materials read as the building file's layers ---------------------------------------------
def test_a_refraction_extinction_pane_is_energyplus_normal_incidence_optics(tmp_path):
    """A 3 mm pane of n = 1.526, K = 30 /m: one face reflects r = (0.526/2.526)^2, the glass passes
    tau = exp(-0.09); with the pane's interreflections T0 = (1 - r)^2 tau / (1 - r^2 tau^2) and
    R0 = r (1 + (1 - r)^2 tau^2 / (1 - r^2 tau^2)). Inverting (T0, R0) gives r and tau back, and the
    window of that pane alone transmits T0 at normal incidence."""
    r, tau = (0.526 / 2.526) ** 2, np.exp(-30 * 0.003)
    T0 = (1 - r) ** 2 * tau / (1 - r ** 2 * tau ** 2)
    R0 = r * (1 + (1 - r) ** 2 * tau ** 2 / (1 - r ** 2 * tau ** 2))
    assert glazing.pane_from_refraction(0.003, 1.526, 30.0) == pytest.approx((T0, R0), rel=1e-12)
    assert glazing.pane_optics(T0, R0) == pytest.approx((r, tau), rel=1e-9)
    text = box_24().replace("WindowMaterial:SimpleGlazingSystem, SGS, 2.0, 0.6;\nConstruction, GLAZING, SGS;\n",
                            "WindowMaterial:Glazing:RefractionExtinctionMethod, GLASS, 0.003, 1.526, 30, 1.526, 30, 0, "
                            "0.84, 0.9, 1, No;\nConstruction, GLAZING, GLASS;\n")
    window = convert_idf(write(tmp_path, text)).component("WIN")
    assert window.solar_transmittance == pytest.approx(T0, abs=1e-6)  # the file keeps 6 decimals
    ((glass, thickness),) = window.layers
    assert thickness == 0.003 and glass.conductivity == 0.9


def test_an_infrared_transparent_layer_is_energyplus_massless_hundredth(tmp_path):
    """Material:InfraredTransparent is a massless 0.01 m2K/W in EnergyPlus, its face absorbing the
    sun wholly and long-wave radiation at 0.9999: the wall R2 + IRT conducts through 2.01 m2K/W,
    its inside face is the transparent layer's, and the transparency is listed."""
    text = box_24().replace("Construction, OPAQUE, R2;", "Material:InfraredTransparent, IRT;\nConstruction, OPAQUE, R2, IRT;")
    b = convert_idf(write(tmp_path, text))
    wall = b.component("N")
    assert sum(t / m.conductivity for m, t in wall.layers) == pytest.approx(2.01, rel=1e-9)
    assert sum(m.density for m, _ in wall.layers) == 0.0
    assert any(line.startswith("Material:InfraredTransparent IRT: a massless layer of resistance 0.01")
               for line in b.data["not_modelled"])


def test_a_vegetated_roof_is_its_dry_soil(tmp_path):
    """Material:RoofVegetation's soil: 0.1 m of dry soil at k 0.4 W/m/K, 641 kg/m3, 1100 J/kg/K,
    outside the roof's R2, its face absorbing the sun at 0.7; the plants are listed as not held."""
    eco = ("Material:RoofVegetation, ECO, 0.2, 5, 0.2, 0.95, 180, SOIL, MediumRough, 0.1, 0.4, 641, 1100, "
           "0.95, 0.7, 0.75, 0.3, 0.01, 0.1, Simple;\nConstruction, GREEN, ECO, R2;\n")
    text = box_24().replace("Construction, OPAQUE, R2;\n", "Construction, OPAQUE, R2;\n" + eco)
    text = text.replace("R, Roof, OPAQUE", "R, Roof, GREEN")
    b = convert_idf(write(tmp_path, text))
    roof = b.component("R")
    soil, thickness = roof.layers[-1]  # the layers run from the inside face outwards
    assert (soil.conductivity, soil.density, soil.specific_heat, thickness) == (0.4, 641.0, 1100.0, 0.1)
    assert sum(t / m.conductivity for m, t in roof.layers) == pytest.approx(2.0 + 0.1 / 0.4, rel=1e-9)
    assert roof.outside.solar_absorptance == 0.7
    assert any(line.startswith("Material:RoofVegetation ECO: its soil layer") for line in b.data["not_modelled"])


@pytest.mark.parametrize("temperatures, taken", [((25, 35), 25), ((15, 20, 30), 20)])
def test_a_thermochromic_group_is_its_pane_nearest_20_c(tmp_path, temperatures, taken):
    """Each temperature's pane transmits a different T0 (0.8 - T/100); the window transmits the
    pane's at 20 C where the group has one, its coolest where all are warmer, and says so."""
    panes = "".join(f"WindowMaterial:Glazing, TC{T}, SpectralAverage, , 0.003, {0.8 - T / 100:g}, 0.08, 0.08, 0.8, "
                    "0.08, 0.08, 0, 0.84, 0.84, 0.9;\n" for T in temperatures)
    group = "WindowMaterial:GlazingGroup:Thermochromic, TC, " + ", ".join(f"{T}, TC{T}" for T in temperatures) + ";\n"
    text = box_24().replace("WindowMaterial:SimpleGlazingSystem, SGS, 2.0, 0.6;\nConstruction, GLAZING, SGS;\n",
                            panes + group + "Construction, GLAZING, TC;\n")
    b = convert_idf(write(tmp_path, text))
    assert b.component("WIN").solar_transmittance == pytest.approx(0.8 - taken / 100, rel=1e-9)
    assert any(line.startswith(f"WindowMaterial:GlazingGroup:Thermochromic TC: its pane at {taken} C")
               for line in b.data["not_modelled"])


def test_a_watts_per_person_gain_stands_on_the_zones_people(tmp_path):
    """EnergyPlus's Watts/Person level is the W a person times the zone's design occupants, the sum
    of its People objects each by its own method: 3 people, plus one per 12 m2 of the 8 x 6 m floor
    (4), plus 0.05 per m2 (2.4): 9.4 people; lights at 10 W and gas equipment at 5 W a person."""
    text = HEADER + zone("Z") + box("Z", "Z") + "Schedule:Constant,\n  ACTIVITY,\n  ,\n  120;\n"
    for name, method, values in (("P1", "People", "3, , "), ("P2", "Area/Person", ", , 12"),
                                 ("P3", "People/Area", ", 0.05, ")):
        text += f"People, {name}, Z, , {method}, {values}, 0.3, 0.6, ACTIVITY;\n"
    text += "Lights, L, Z, , Watts/Person, , , 10, 0, 0.4, 0.2, 1;\n"
    text += "GasEquipment, G, Z, , Watts/Person, , , 5, 0, 0.3, 0;\n"
    gains = {g.name: g for g in convert_idf(write(tmp_path, text)).zone("Z").gains}
    assert gains["L"].power == pytest.approx(10 * (3 + 48 / 12 + 0.05 * 48), rel=1e-9)
    assert gains["G"].power == pytest.approx(5 * (3 + 48 / 12 + 0.05 * 48), rel=1e-9)
    assert gains["P1"].power == pytest.approx(3 * 120 * 0.6, rel=1e-9)


def test_an_air_boundary_exchanges_the_smaller_zones_volume_both_ways(tmp_path):
    """three_zones.idf with the west office's wall to the corridor an air boundary of SimpleMixing
    at 2 /h: EnergyPlus makes a ZoneMixing each way of 2 x the smaller zone's volume (the office's
    6 x 5 x 3 m, 90 m3, beside the corridor's 108), 180 m3/h. The wall conducts nothing, every other
    component is as before, and the opening's radiant and solar exchange are listed."""
    text = MULTIZONE.read_text()
    for name in ("WEST TO CORRIDOR", "CORRIDOR TO WEST"):
        text = text.replace(f"    {name},Wall,INT WALL,", f"    {name},Wall,AIR WALL,")
    # 9.3's fields: the solar and radiant methods (grouped zones), then the air exchange
    text += "Construction:AirBoundary, AIR WALL, GroupedZones, GroupedZones, SimpleMixing, 2, ;\n"
    b, before = convert_idf(write(tmp_path, text)), convert_idf(MULTIZONE)
    assert [(f.zone, f.flow) for f in b.zone("WEST OFFICE").airflow_from] == [("CORRIDOR", pytest.approx(180.0))]
    assert [(f.zone, f.flow) for f in b.zone("CORRIDOR").airflow_from] == [("WEST OFFICE", pytest.approx(180.0))]
    assert b.zone("EAST OFFICE").airflow_from == ()
    assert {c.name for c in before.components} - {c.name for c in b.components} == {"WEST TO CORRIDOR"}
    assert any(line.startswith("Construction:AirBoundary AIR WALL between CORRIDOR and WEST OFFICE")
               for line in b.data["not_modelled"])
    none = convert_idf(write(tmp_path, text.replace("SimpleMixing, 2", "None, 2"), "none.idf"))
    assert none.zone("WEST OFFICE").airflow_from == () and none.zone("CORRIDOR").airflow_from == ()


def test_a_gain_or_flow_naming_a_space_acts_on_its_zone_with_the_spaces_floor(tmp_path):
    """The 4 x 4 m zone Z holds space S1 (its floor surface, 16 m2) and S2 (6 m2 by its Floor Area
    field, after 24.1's Ceiling Height and Volume). Lights of 10 W/m2 on S1 give 160 W; of 5 W/m2 on the SpaceList of both, 5 x 22 = 110 W;
    of 20 W a person on S2 with its 2 people, 40 W; 100 W of equipment on S2 is 100 W; an
    infiltration of 0.001 m3/s per m2 of S2 is 0.006 m3/s, 21.6 m3/h of the zone's air."""
    text = box_24().replace("F, Floor, OPAQUE, Z, ,", "F, Floor, OPAQUE, Z, S1,")
    text += ("Space, S1, Z, , , , Office;\nSpace, S2, Z, , , 6, Office;\nSpaceList, BOTH, S1, S2;\n"
             "Schedule:Constant, ACTIVITY, , 120;\n"
             "Lights, L1, S1, , Watts/Area, , 10, , 0, 0.4, 0.2, 1;\n"
             "Lights, L2, BOTH, , Watts/Area, , 5, , 0, 0.4, 0.2, 1;\n"
             "Lights, L3, S2, , Watts/Person, , , 20, 0, 0.4, 0.2, 1;\n"
             "People, P, S2, , People, 2, , , 0.3, 0.6, ACTIVITY;\n"
             "ElectricEquipment, E, S2, , EquipmentLevel, 100, , , 0, 0.3, 0;\n"
             "ZoneInfiltration:DesignFlowRate, I, S2, , Flow/Area, , 0.001, , , 1, 0, 0, 0;\n")
    b = convert_idf(write(tmp_path, text))
    z = b.zone("Z")
    gains = {g.name: g.power for g in z.gains}
    assert gains == pytest.approx({"L1": 160.0, "L2": 110.0, "L3": 40.0, "P": 2 * 120 * 0.6, "E": 100.0}, rel=1e-9)
    assert z.air_change_rate * z.volume == pytest.approx(21.6, rel=1e-9)
