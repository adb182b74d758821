"""The ASHRAE 140 free-float cases as EnergyPlus models, made from NREL's published IDFs (data/,
README.md) by the edits the standard defines, through idfkit, so that `nodeforce convert` is what
`make bestest` tests:

- 600FF: case 600 (data/case_en_600.idf, EnergyPlus 9.3) without its thermostat and ideal loads
  (the standard's free float: no heating or cooling);
- 650FF: 600FF with case 950FF's night ventilation (its infiltration object and schedules: the
  vent's 1703 m3/h and the infiltration's 0.5 air changes an hour from 18:00 to 07:00, the
  infiltration alone by day);
- 900FF: case 950FF (data/950FF_test_output.idf, EnergyPlus 8.8: case 900's heavy walls and floor,
  free-floating) with case 900's constant infiltration, 0.5 air changes an hour, in place of the
  night ventilation of 950;
- 950FF: case 950FF as published;
- 680FF and 980FF: 600FF and 900FF with the standard's increased insulation, as NREL's
  BESTEST-GSR measure sets it (`set_wall_roof_insulation`: the exterior wall's second layer
  0.25 m of foam, 0.04 W/m/K, 10 kg/m3, 1400 J/kg/K; the roof's 0.4 m of fiberglass quilt,
  0.04 W/m/K, 12 kg/m3, 840 J/kg/K).

    python examples/bestest/cases.py OUT_FOLDER     writes OUT_FOLDER/<case>.idf



"""
import sys
from pathlib import Path

import idfkit

DATA = Path(__file__).with_name("data")
# What a free-floating case has no use for: the zone's thermostat and its ideal loads system
HVAC = ("ZoneControl:Thermostat", "ThermostatSetpoint:DualSetpoint", "ZoneHVAC:EquipmentConnections",
        "ZoneHVAC:EquipmentList", "ZoneHVAC:IdealLoadsAirSystem", "NodeList", "OutdoorAir:Node")


def free_float(doc):
    for kind in HVAC:
        for obj in list(doc[kind]):
            doc.removeidfobject(obj)
    return doc


def case_600ff():
    return free_float(idfkit.load_idf(str(DATA / "case_en_600.idf")))


def night_ventilation():
    """Case 950FF's night ventilation: its infiltration object and the schedules it needs."""
    return idfkit.load_idf(str(DATA / "950FF_test_output.idf"), version=(8, 9, 0))


def case_650ff():
    doc, vent = case_600ff(), night_ventilation()
    for obj in list(doc["ZoneInfiltration:DesignFlowRate"]):
        doc.removeidfobject(obj)
    (infiltration,) = vent["ZoneInfiltration:DesignFlowRate"]
    year = vent.getobject("SCHEDULE:YEAR", infiltration.schedule_name)
    # the 8.8 file numbers a year's weeks (schedule_week_name_1, ...); 9.3 lists them
    fields = year.to_dict()
    weeks = [{f: fields[f"{f}_{k}"] for f in ("schedule_week_name", "start_month", "start_day", "end_month", "end_day")}
             for k in range(1, 54) if f"schedule_week_name_{k}" in fields]
    week_objs = [vent.getobject("SCHEDULE:WEEK:DAILY", w["schedule_week_name"]) for w in weeks]
    days = {d for w in week_objs for k, d in w.to_dict().items() if k != "name"}
    for obj in [vent.getobject("SCHEDULETYPELIMITS", year.schedule_type_limits_name), *week_objs,
                *(vent.getobject("SCHEDULE:DAY:INTERVAL", d) for d in days), infiltration]:
        if doc.getobject(obj.obj_type.upper(), obj.name) is None:
            doc.add(obj.obj_type, obj.name, {k: v for k, v in obj.to_dict().items() if k != "name"})
    doc.add("Schedule:Year", year.name, {"schedule_type_limits_name": year.schedule_type_limits_name,
                                          "schedule_weeks": weeks})
    return doc


def case_900ff():
    doc = free_float(idfkit.load_idf(str(DATA / "950FF_test_output.idf"), version=(8, 9, 0)))
    for infiltration in doc["ZoneInfiltration:DesignFlowRate"]:
        infiltration.schedule_name = "Always On Continuous"
        infiltration.design_flow_rate_calculation_method = "AirChanges/Hour"
        infiltration.design_flow_rate = ""
        infiltration.air_changes_per_hour = 0.5
    return doc


def case_950ff():
    return free_float(night_ventilation())


# The standard's increased insulation (cases 680 and 980): the exterior wall's and the roof's
# second layer, outside first, (thickness m, conductivity W/m/K, density kg/m3, specific heat J/kg/K)
WALL_INSULATION = (0.25, 0.04, 10.0, 1400.0)
ROOF_INSULATION = (0.4, 0.04, 12.0, 840.0)


def increased_insulation(doc):
    for surface in doc["BuildingSurface:Detailed"]:
        kind = str(surface.surface_type).lower()
        if str(surface.outside_boundary_condition).lower() != "outdoors" or kind not in ("wall", "roof"):
            continue
        construction = doc.getobject("CONSTRUCTION", surface.construction_name)
        material = doc.getobject("MATERIAL", construction.layer_2)
        thickness, conductivity, density, specific_heat = WALL_INSULATION if kind == "wall" else ROOF_INSULATION
        material.thickness, material.conductivity = thickness, conductivity
        material.density, material.specific_heat = density, specific_heat
    return doc


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
