"""The ASHRAE 140 free-float cases as EnergyPlus models, all made from nodeforce's own case 600
(case600.idf, written from ANSI/ASHRAE Standard 140-2020 section 7.2.1) by the edits the standard
defines for each case, through idfkit, so that `nodeforce convert` is what `make bestest` tests:

- 600FF: case600.idf as written (no thermostat, no heating or cooling);
- 900FF: the high-mass case: the exterior walls' concrete block and foam, the floor's concrete
  slab over its insulation (the roof and the windows as 600);
- 650FF and 950FF: 600FF and 900FF with the night ventilation: a fan of 1703.16 m3/h from 18:00
  to 07:00, besides the infiltration, no fan heat;
- 680FF and 980FF: 600FF and 900FF with the increased insulation (the exterior walls' and the
  roof's insulating layer thickened, as NREL's BESTEST-GSR measure `set_wall_roof_insulation`
  sets it).

    python examples/bestest/cases.py OUT_FOLDER     writes OUT_FOLDER/<case>.idf
"""
import sys
from pathlib import Path

import idfkit

CASE600 = Path(__file__).with_name("case600.idf")
ZONE = "CASE 600 ZONE"

# Case 900's high-mass layers (thickness m, conductivity W/m/K, density kg/m3, specific heat J/kg/K),
# ASHRAE 140-2020 section 7.2.2 (case 900)
CONCRETE_BLOCK = (0.100, 0.510, 1400.0, 1000.0)
FOAM_INSULATION = (0.0615, 0.040, 10.0, 1400.0)
CONCRETE_SLAB = (0.080, 1.130, 1400.0, 1000.0)
HEAVY_FLOOR_INSULATION = 1.007 / 0.040  # m2K/W: 1.007 m at 0.040 W/m/K, its capacity negligible
# Cases 650 and 950: the vent fan's flow (m3/s) and when it runs
NIGHT_VENT_FLOW = 1703.16 / 3600
NIGHT_VENT_OFF, NIGHT_VENT_ON = "07:00", "18:00"
# Cases 680 and 980: the exterior wall's and the roof's insulating (second) layer, outside first
WALL_INSULATION = (0.25, 0.04, 10.0, 1400.0)
ROOF_INSULATION = (0.4, 0.04, 12.0, 840.0)


def material(doc, name, layer, roughness="Rough"):
    thickness, conductivity, density, specific_heat = layer
    doc.add("Material", name, {"roughness": roughness, "thickness": thickness, "conductivity": conductivity,
                               "density": density, "specific_heat": specific_heat, "thermal_absorptance": 0.9,
                               "solar_absorptance": 0.6, "visible_absorptance": 0.6})


def surfaces(doc, kind):
    return [s for s in doc["BuildingSurface:Detailed"] if str(s.surface_type).lower() == kind]


def case_600ff():
    return idfkit.load_idf(str(CASE600))


def high_mass(doc):
    """Case 900: the exterior walls and the floor of concrete; the roof, windows and all else as 600."""
    material(doc, "CONCRETE BLOCK", CONCRETE_BLOCK, "Smooth")
    material(doc, "FOAM INSULATION", FOAM_INSULATION)
    material(doc, "CONCRETE SLAB", CONCRETE_SLAB, "Smooth")
    doc.add("Material:NoMass", "HEAVY FLOOR INSULATION",
            {"roughness": "Rough", "thermal_resistance": HEAVY_FLOOR_INSULATION, "thermal_absorptance": 0.9,
             "solar_absorptance": 0.6, "visible_absorptance": 0.6})
    doc.add("Construction", "HEAVY WALL", {"outside_layer": "WOOD SIDING", "layer_2": "FOAM INSULATION",
                                           "layer_3": "CONCRETE BLOCK"})
    doc.add("Construction", "HEAVY FLOOR", {"outside_layer": "HEAVY FLOOR INSULATION", "layer_2": "CONCRETE SLAB"})
    for wall in surfaces(doc, "wall"):
        wall.construction_name = "HEAVY WALL"
    for floor in surfaces(doc, "floor"):
        floor.construction_name = "HEAVY FLOOR"
    return doc


def night_ventilation(doc):
    """Cases 650 and 950: the vent fan on from 18:00 to 07:00, off by day, the infiltration kept."""
    doc.add("Schedule:Compact", "NIGHT VENT", {"schedule_type_limits_name": "Fraction", "data": [
        {"field": "Through: 12/31"}, {"field": "For: AllDays"},
        {"field": f"Until: {NIGHT_VENT_OFF}"}, {"field": "1"},
        {"field": f"Until: {NIGHT_VENT_ON}"}, {"field": "0"},
        {"field": "Until: 24:00"}, {"field": "1"}]})
    doc.add("ZoneVentilation:DesignFlowRate", "NIGHT VENT FAN", {
        "zone_or_zonelist_name": ZONE, "schedule_name": "NIGHT VENT", "design_flow_rate_calculation_method": "Flow/Zone",
        "design_flow_rate": NIGHT_VENT_FLOW, "ventilation_type": "Intake", "fan_pressure_rise": 0.0,
        "fan_total_efficiency": 1.0, "constant_term_coefficient": 1.0, "temperature_term_coefficient": 0.0,
        "velocity_term_coefficient": 0.0, "velocity_squared_term_coefficient": 0.0})
    return doc


def increased_insulation(doc):
    """Cases 680 and 980: the exterior walls' and the roof's second layer, outside first, thickened."""
    for kind, layer in (("wall", WALL_INSULATION), ("roof", ROOF_INSULATION)):
        constructions = {s.construction_name for s in surfaces(doc, kind)
                         if str(s.outside_boundary_condition).lower() == "outdoors"}
        for name in constructions:
            m = doc.getobject("MATERIAL", doc.getobject("CONSTRUCTION", name).layer_2)
            m.thickness, m.conductivity, m.density, m.specific_heat = layer
    return doc


def case_900ff():
    return high_mass(case_600ff())


def case_650ff():
    return night_ventilation(case_600ff())


def case_950ff():
    return night_ventilation(case_900ff())


def case_680ff():
    return increased_insulation(case_600ff())


def case_980ff():
    return increased_insulation(case_900ff())


CASES = {"600FF": case_600ff, "900FF": case_900ff, "650FF": case_650ff, "950FF": case_950ff,
         "680FF": case_680ff, "980FF": case_980ff}


def main(out):
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    for name, make in CASES.items():
        idfkit.save_idf(make(), str(out / f"{name}.idf"))
        print(f"wrote {out / f'{name}.idf'}")


if __name__ == "__main__":
    main(sys.argv[1])
