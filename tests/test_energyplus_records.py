"""The records of the diagnosis benchmark whose truth is EnergyPlus (benchmarks/energyplus_records.py,
benchmarks/bench_energyplus_diagnosis.py), without EnergyPlus: each change edits the named field
of the IDF by the named amount and nothing the diagnosis reads besides (the changed IDF written
and read back with idfkit); the judging on hand-made answers; the noise's draws.
"""
import math

import idfkit
import numpy as np
import pandas as pd
import pytest

from benchmarks import energyplus_records as records
from benchmarks.bench_energyplus_diagnosis import summary
from benchmarks.bench_diagnosis import held, right

ZONE = records.ZONE


def read_back(spec, tmp_path):
    """The record's changed IDF written and read again; and the unchanged one."""
    path = tmp_path / f"{spec.replace('/', '_')}.idf"
    idfkit.save_idf(records.changed_document(records.SPECS_BY_NAME[spec]), str(path))
    return idfkit.load_idf(str(path)), records.building_document(spec.split("/")[0])


def construction_layers(doc, surface):
    s = doc.getobject("BUILDINGSURFACE:DETAILED", surface)
    c = doc.getobject("CONSTRUCTION", s.construction_name)
    return [getattr(c, f) for f in ["outside_layer"] + [f"layer_{k}" for k in range(2, 11)] if getattr(c, f, None)]


def material(doc, name):
    return doc.getobject("MATERIAL", name) or doc.getobject("MATERIAL:NOMASS", name)


def test_air_change_is_three_times_the_declared(tmp_path):
    for building in records.BUILDINGS:
        spec = f"{building}/air-change"
        changed, original = read_back(spec, tmp_path)
        before, = original["ZoneInfiltration:DesignFlowRate"]
        after, = changed["ZoneInfiltration:DesignFlowRate"]
        assert float(before.air_changes_per_hour) == 0.5  # ASHRAE 140's
        assert float(after.air_changes_per_hour) == pytest.approx(1.5)
        assert after.design_flow_rate_calculation_method == before.design_flow_rate_calculation_method


@pytest.mark.parametrize("building, insulation, k", [("600FF", "WALL FIBERGLASS QUILT", 0.040),
                                                      ("900FF", "FOAM INSULATION", 0.040)])
def test_walls_insulation_twice_as_conductive_and_nothing_else(building, insulation, k, tmp_path):
    changed, original = read_back(f"{building}/insulation", tmp_path)
    for wall in records.WALLS:
        before, after = construction_layers(original, wall), construction_layers(changed, wall)
        assert len(before) == len(after)
        for b, a in zip(before, after):
            mb, ma = material(original, b), material(changed, a)
            if b == insulation:
                assert float(mb.conductivity) == k
                assert float(ma.conductivity) == pytest.approx(2 * k)
                assert (ma.thickness, ma.density, ma.specific_heat) == (mb.thickness, mb.density, mb.specific_heat)
            else:
                assert a == b
    # the roof and the floor keep their constructions, and every shared material its value
    for surface in ("ROOF", "FLOOR"):
        assert construction_layers(changed, surface) == construction_layers(original, surface)
    assert float(material(changed, insulation).conductivity) == k


def test_furniture_is_an_internal_mass_of_the_named_wood(tmp_path):
    for building in records.BUILDINGS:
        changed, original = read_back(f"{building}/furniture", tmp_path)
        assert len(original["InternalMass"]) == 0
        mass, = changed["InternalMass"]
        assert float(mass.surface_area) == records.FURNITURE_AREA
        layers = [changed.getobject("CONSTRUCTION", mass.construction_name).outside_layer]
        wood = material(changed, layers[0])
        thickness, conductivity, density, specific_heat = records.FURNITURE_LAYER
        assert (float(wood.thickness), float(wood.conductivity), float(wood.density), float(wood.specific_heat)) == \
            (thickness, conductivity, density, specific_heat)
        # its capacity, both sides of the slab facing the zone: 30 m2 x 0.025 m x 600 kg/m3 x 1600 J/kg/K
        assert float(mass.surface_area) * thickness * density * specific_heat == pytest.approx(720e3)


def test_glass_transmits_six_tenths_of_the_declared(tmp_path):
    changed, original = read_back("600FF/glass", tmp_path)
    for before, after in zip(original["WindowMaterial:Glazing"], changed["WindowMaterial:Glazing"]):
        assert float(before.solar_transmittance_at_normal_incidence) == 0.86156
        assert float(after.solar_transmittance_at_normal_incidence) == pytest.approx(0.6 * 0.86156)
        # the rest of the pane as declared: its reflectances, its visible transmittance
        for field in ("front_side_solar_reflectance_at_normal_incidence", "visible_transmittance_at_normal_incidence"):
            assert getattr(after, field) == getattr(before, field)


def test_office_gain_is_300_w_on_weekdays_from_8_to_18(tmp_path):
    changed, original = read_back("600FF/gain", tmp_path)
    assert len(original["ElectricEquipment"]) == 0
    gain, = changed["ElectricEquipment"]
    assert float(gain.design_level) == 300.0
    assert str(gain.zone_or_zonelist_name).upper() == ZONE
    schedule = changed.getobject("SCHEDULE:COMPACT", gain.schedule_name)
    fields = [f["field"] if isinstance(f, dict) else f for f in schedule.to_dict()["data"]]
    assert fields == ["Through: 12/31", "For: Weekdays", "Until: 08:00", 0, "Until: 18:00", 1, "Until: 24:00", 0,
                      "For: AllOtherDays", "Until: 24:00", 0]


def test_roof_absorbs_nine_tenths_of_the_sun_and_the_walls_as_declared(tmp_path):
    for building in records.BUILDINGS:
        changed, original = read_back(f"{building}/roof", tmp_path)
        outside = material(changed, construction_layers(changed, "ROOF")[0])
        assert float(material(original, construction_layers(original, "ROOF")[0]).solar_absorptance) == 0.6
        assert float(outside.solar_absorptance) == 0.9
        assert construction_layers(changed, "ROOF")[1:] == construction_layers(original, "ROOF")[1:]
        for wall in records.WALLS:
            assert construction_layers(changed, wall) == construction_layers(original, wall)


def test_the_faultless_record_is_the_building_as_written(tmp_path):
    for building in records.BUILDINGS:
        changed, original = read_back(f"{building}/none", tmp_path)
        assert sorted((o.obj_type, str(o.to_dict())) for o in changed.all_objects) == \
            sorted((o.obj_type, str(o.to_dict())) for o in original.all_objects)


def test_energyplus_runs_the_record_and_the_later_record_at_1_min_steps():
    doc = records.run_document(records.building_document("600FF"))
    timestep, = doc["Timestep"]
    assert int(timestep.number_of_timesteps_per_hour) == 60  # its answer converged in time
    period, = doc["RunPeriod"]
    p = records.periods()
    assert (int(period.begin_month), int(period.begin_day_of_month)) == (3, 18)  # 14 days before 1 April
    # the later record: from 28 days after 1 April, 14 days on, for 28 days: 13 May to 9 June inclusive
    assert p["later"][0] == pd.Timestamp("2017-05-13 00:10") and p["later"][1] == pd.Timestamp("2017-06-10 00:00")
    assert (int(period.end_month), int(period.end_day_of_month)) == (6, 9)
    assert {o.reporting_frequency for o in doc["Output:Variable"]} == {"Timestep"}


def test_steps_keep_the_times_energyplus_gives():
    table = pd.DataFrame({"Date/Time": [" 04/01  00:10:00", " 04/01  24:00:00"],
                          "CASE 600 ZONE:Zone Mean Air Temperature [C](TimeStep)": [20.0, 21.0],
                          "ROOF:Surface Inside Face Temperature [C](TimeStep)": [19.0, 18.0]})
    steps = records.read_steps(table)
    assert list(steps.index) == [pd.Timestamp("2017-04-01 00:10"), pd.Timestamp("2017-04-02 00:00")]
    assert list(steps.columns) == [ZONE, "ROOF"]


def test_the_sensors_read_every_10_min_of_energyplus_1_min_steps():
    first, last = records.periods()["record"]
    times = pd.date_range(first - pd.Timedelta(minutes=9), last, freq="1min")
    minutes = (times - times[0]).total_seconds().to_numpy() / 60.0
    steps = pd.DataFrame({ZONE: minutes, "ROOF": -minutes}, index=times)
    part = records.sample(steps, "record", {"T44": ZONE, "T36": "ROOF"}, -6.0)
    assert part.index[0].isoformat() == "2017-04-01T00:10:00-06:00"
    assert len(part) == records.DAYS * 144
    # each reading is EnergyPlus's step ending at its time: 9 + 10 k minutes after the first step
    assert np.array_equal(part["T44"].to_numpy(), 9.0 + 10.0 * np.arange(len(part)))
    assert np.array_equal(part["T36"].to_numpy(), -part["T44"].to_numpy())
    with pytest.raises(KeyError):  # a reading EnergyPlus has no step for is not invented
        records.sample(steps.drop(pd.Timestamp("2017-04-10 12:00")), "record", {"T44": ZONE}, -6.0)


def test_noise_is_the_same_for_the_same_record_and_draw():
    times = pd.date_range("2017-04-01 00:10", periods=20000, freq="10min", tz="Etc/GMT+6")
    clean = pd.DataFrame({"T44": np.full(len(times), 20.0), "T1": np.full(len(times), 15.0)}, index=times)
    a = records.noisy(clean, "600FF/glass", 0)
    assert a.equals(records.noisy(clean, "600FF/glass", 0))
    assert not np.allclose(a, records.noisy(clean, "600FF/glass", 1))
    assert not np.allclose(a, records.noisy(clean, "900FF/glass", 0))
    d = (a - clean).to_numpy()
    # 40 000 draws of N(0, 0.1): the mean's standard error 0.0005 C, the sd's 0.00035 C
    assert abs(d.mean()) < 0.002 and d.std() == pytest.approx(records.NOISE, abs=0.0015)


def answered(change, effects, later=(0.3, 0.3)):
    """A hand-made result of the record 600FF/`change`: the effects added, the later RMSEs."""
    spec = records.SPECS_BY_NAME[f"600FF/{change}"]
    return {"name": spec.name, "draw": 0, "fault": spec.label, "noise": 0.1,
            "faults": [[list(a) for a in spec.answers]] if spec.answers else [],
            "loop": {"effects": [list(e) for e in effects], "before": 1.0, "after": 0.5, "seconds": 1.0},
            "idf_changes": [], "not_written": [], "record_energyplus_vs_truth": 1.0,
            "later": {"written": later[0], "corrected": later[1]}}


@pytest.mark.parametrize("change, effect, is_right", [
    ("air-change", ("infiltration", ZONE), True),
    ("air-change", ("thermal_bridge", ZONE), True),
    ("air-change", ("envelope_conductance", ZONE), False),
    ("insulation", ("conductivity", "NORTH WALL"), True),
    ("insulation", ("envelope_conductance", ZONE), True),
    ("insulation", ("conductivity", "ROOF"), False),
    ("furniture", ("internal_mass", ZONE), True),
    ("furniture", ("inside_convection", ZONE), False),
    ("glass", ("solar_transmittance", "SOUTH WINDOW EAST"), True),
    ("glass", ("envelope_conductance", ZONE), False),
    ("gain", ("daily_gain", ZONE), True),
    ("gain", ("internal_gain", ZONE), True),
    ("gain", ("proportional_gain", f"{ZONE}->I_EAST WALL"), False),
    ("roof", ("solar_absorptance", "ROOF"), True),
    ("roof", ("solar_absorptance", "NORTH WALL"), False),
    ("none", ("inside_convection", ZONE), False),
])
def test_first_effect_judged_by_the_change(change, effect, is_right):
    assert right(answered(change, [effect, ("internal_mass", ZONE)]), "loop") is is_right


def test_nothing_added_is_right_only_without_a_change():
    assert right(answered("none", []), "loop")
    assert not right(answered("glass", []), "loop")


def test_later_record_holds_within_one_and_a_half_noise():
    assert held(answered("glass", [], later=(0.30, 0.30)))
    assert held(answered("glass", [], later=(0.05, 0.15)))  # worse, but within 1.5 x 0.1 C
    assert not held(answered("glass", [], later=(0.05, 0.16)))
    assert not held(answered("glass", [], later=(0.30, 0.31)))


def test_summary_counts_the_criteria():
    results = [answered("glass", [("solar_transmittance", "SOUTH WINDOW WEST")]),
               answered("roof", [("inside_convection", ZONE)], later=(0.3, 0.5)),
               answered("none", []), answered("none", [("daily_gain", ZONE)]),
               {"name": "900FF/gain", "draw": 0, "error": "RuntimeError: EnergyPlus failed"}]
    lines, numbers = summary(results, 1)
    assert numbers["right"] == 0.5 and numbers["clean_untouched"] == 0.5 and numbers["carried"] == 0.75
    assert numbers["failed"] == 1 and numbers["diagnoses"] == 4
    assert any(line.startswith("- FAIL: first effect right on 50 %") for line in lines)
    assert not math.isnan(numbers["seconds_median"])


def test_the_building_stands_where_its_weather_was_recorded():
    """EnergyPlus run on a weather file takes the file's location, not the IDF's (its eplusout.err:
    "Weather file location will be used rather than entered (IDF) Location object"): the records'
    IDF, which nodeforce converts, is given the EPW's LOCATION line, O'Hare's 41.98 N, 87.92 W,
    UTC-6, 201 m, in place of ASHRAE 140's Denver, and holds no other site."""
    for building in records.BUILDINGS:
        sites = list(records.building_document(building).idfobjects["Site:Location"])
        assert len(sites) == 1
        site = sites[0]
        assert (site.latitude, site.longitude, site.time_zone, site.elevation) == (41.98, -87.92, -6.0, 201.0)
