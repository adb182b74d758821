"""The ASHRAE 140 free-float cases as EnergyPlus models, made from NREL's published IDFs (data/,
README.md) by the edits the standard defines, through idfkit, so that `nodeforce convert` is what
`make bestest` tests:

- 600FF: case 600 (data/case_en_600.idf, EnergyPlus 9.3) without its thermostat and ideal loads
  (the standard's free float: no heating or cooling);
- 900FF: case 950FF (data/950FF_test_output.idf, EnergyPlus 8.8: case 900's heavy walls and floor,
  free-floating) with case 900's constant infiltration, 0.5 air changes an hour, in place of the
  night ventilation of 950.

    python examples/bestest/cases.py OUT_FOLDER     writes OUT_FOLDER/600FF.idf, 900FF.idf

650FF and 950FF need a ventilation scheduled by the hour, which the building file's constant air
flows cannot hold: `nodeforce convert` refuses them (docs/guide.md).
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


def case_900ff():
    doc = free_float(idfkit.load_idf(str(DATA / "950FF_test_output.idf"), version=(8, 9, 0)))
    for infiltration in doc["ZoneInfiltration:DesignFlowRate"]:
        infiltration.schedule_name = "Always On Continuous"
        infiltration.design_flow_rate_calculation_method = "AirChanges/Hour"
        infiltration.design_flow_rate = ""
        infiltration.air_changes_per_hour = 0.5
    return doc


CASES = {"600FF": case_600ff, "900FF": case_900ff}


def main(out):
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    for name, make in CASES.items():
        idfkit.save_idf(make(), str(out / f"{name}.idf"))
        print(f"wrote {out / f'{name}.idf'}")


if __name__ == "__main__":
    main(sys.argv[1])
