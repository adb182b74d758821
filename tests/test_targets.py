"""Effects on a construction or a material shared by several surfaces: the building file's
`constructions` group its components, a surface effect may target a group with one parameter for
all its members, the diagnosis offers the groups, and the write-back edits the Construction or
Material object itself."""
import copy
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from nodeforce.api import convert_idf
from nodeforce.diagnosis.candidates import component_effects
from nodeforce.model.building_file import parse_building
from nodeforce.model.effects import EFFECTS, members
from nodeforce.model.errors import InputError
from nodeforce.model.integrate import simulate
from nodeforce.model.network import assemble

CASE600 = Path(__file__).resolve().parents[1] / "examples" / "bestest" / "case600.idf"
WALLS = ["east_wall", "west_wall", "south_wall", "north_wall"]


def two_windows(testcell_data, constructions=True):
    """The test cell with a second window, west, of the south one's glazing (0.8 m2 cut from the
    west wall), and, where `constructions`, its walls and its windows declared as built of one
    construction each, the door of its own."""
    data = copy.deepcopy(testcell_data)
    window = next(c for c in data["components"] if c["name"] == "window")
    west = dict(copy.deepcopy(window), name="west_window", azimuth=270.0,
                nodes=[{"id": 24, "depth": 0.0}, {"id": 25, "depth": 0.004}])
    next(c for c in data["components"] if c["name"] == "west_wall")["area"] -= west["area"]
    data["components"].append(west)
    if constructions:
        data["constructions"] = {"walls": WALLS, "glazing": ["window", "west_window"], "door": ["door"]}
    return data


def direct(b, case):
    return simulate(b, assemble(b), case.U, case.dt, case.measured, substeps=case.substeps)


def test_a_file_without_constructions_offers_its_components_alone(testcell_data, testcell):
    names = [c["name"] for c in testcell_data["components"]]
    assert EFFECTS["conductivity"].targets(testcell) == names
    assert EFFECTS["solar_transmittance"].targets(testcell) == ["window"]
    assert EFFECTS["solar_absorptance"].targets(testcell) == [n for n in names if n != "floor"]
    assert parse_building(two_windows(testcell_data, constructions=False)).constructions == {}


def test_the_groups_are_the_constructions_and_shared_materials_of_two_or_more_components(testcell_data):
    b = parse_building(two_windows(testcell_data))
    # the door's construction is the door alone; the glass makes up the glazing's components
    # alone, so scaling it is scaling the construction: neither is a target of its own
    assert EFFECTS["conductivity"].targets(b)[-4:] == ["construction:walls", "construction:glazing",
                                                       "material:fibre_cement", "material:polyurethane"]
    assert EFFECTS["solar_transmittance"].targets(b) == ["window", "west_window", "construction:glazing"]
    # fibre cement and polyurethane are the walls' and the roof's
    assert set(members(b, "material:polyurethane")) == {*WALLS, "roof"}
    # a glazing's transmittance is offered where its sun lands, its construction's too, once
    assert component_effects(b, "floor").count(("solar_transmittance", "construction:glazing")) == 1
    assert ("solar_transmittance", "construction:glazing") in component_effects(b, "west_window")
    assert ("conductivity", "material:polyurethane") in component_effects(b, "roof")


def test_a_groups_effect_is_the_effect_on_each_member(testcell_data):
    b = parse_building(two_windows(testcell_data))
    for effect, group, values in [("solar_transmittance", "construction:glazing", {"tau": 0.55}),
                                  ("solar_absorptance", "construction:walls", {"alpha": 0.8}),
                                  ("conductivity", "construction:walls", {"factor": 1.7})]:
        one_by_one = b
        for name in members(b, group):
            one_by_one = EFFECTS[effect].apply(one_by_one, name, values)
        grouped = EFFECTS[effect].apply(b, group, values)
        assert grouped.components == one_by_one.components, effect
        assert EFFECTS[effect].read(grouped, group) == values


def test_a_materials_factor_is_its_conductivity_scaled_in_every_layer(testcell_data, weather):
    from nodeforce.model.case import prepare_case
    from nodeforce.model.synth import pseudo_measurements
    data = two_windows(testcell_data)
    b = parse_building(data)
    times = pd.date_range("2001-06-10", periods=2 * 96 + 1, freq="15min", tz="-05:00", name="time")
    case = prepare_case(b, weather, pseudo_measurements(b, weather, times, [23]))
    scaled = copy.deepcopy(data)
    scaled["materials"]["polyurethane"]["conductivity"] *= 2.5
    by_factor = EFFECTS["conductivity"].apply(b, "material:polyurethane", {"factor": 2.5})
    assert by_factor.data["materials"]["polyurethane"]["conductivity_factor"] == 2.5
    assert np.abs(direct(by_factor, case) - direct(parse_building(scaled), case)).max() < 1e-9
    assert np.abs(direct(by_factor, case) - direct(b, case)).max() > 0.05


def test_a_groups_fmu_parameter_is_the_group_declared(tmp_path, testcell_data, weather):
    from nodeforce.cosim.fmi import FmuInstance
    from nodeforce.cosim.run import simulate_fmu
    from nodeforce.fmu_build.build import build_fmu
    from nodeforce.model.case import prepare_case
    from nodeforce.model.synth import pseudo_measurements
    b = parse_building(two_windows(testcell_data))
    times = pd.date_range("2001-06-10", periods=2 * 96 + 1, freq="15min", tz="-05:00", name="time")
    case = prepare_case(b, weather, pseudo_measurements(b, weather, times, [23]))
    fmu = build_fmu(b, tmp_path / "m.fmu", effect=("solar_transmittance", "construction:glazing"))
    with FmuInstance(fmu) as instance:
        changed = simulate_fmu(instance, case, parameters={"solar_transmittance.tau": 0.3})
    expected = direct(EFFECTS["solar_transmittance"].apply(b, "construction:glazing", {"tau": 0.3}), case)
    assert np.abs(changed - expected).max() < 1e-9
    assert np.abs(changed - direct(b, case)).max() > 0.5


@pytest.mark.parametrize("constructions, where, says", [
    ({"glazing": ["window", "skylight"]}, r"constructions\.glazing\[1\]", "names no component \\('skylight'\\)"),
    ({"glazing": ["window"], "glass": ["window"]}, r"constructions\.glass\[0\]",
     "'window' is built of 'glazing' already"),
])
def test_a_construction_naming_an_unknown_or_taken_component_is_refused(testcell_data, constructions, where, says):
    data = dict(copy.deepcopy(testcell_data), constructions=constructions)
    with pytest.raises(InputError, match=f"<building>: {where}: {says}"):
        parse_building(data)


def test_the_converter_groups_the_surfaces_as_the_idfs_constructions(tmp_path):
    b = convert_idf(CASE600, tmp_path / "600.json")
    assert sorted(b.constructions["LIGHT WALL"]) == ["EAST WALL", "NORTH WALL", "SOUTH WALL", "WEST WALL"]
    assert sorted(b.constructions["DOUBLE CLEAR"]) == ["SOUTH WINDOW EAST", "SOUTH WINDOW WEST"]
    assert "material:WALL FIBERGLASS QUILT" in EFFECTS["conductivity"].targets(b)


def test_a_group_is_written_back_into_its_construction_or_material(tmp_path):
    import idfkit
    from nodeforce.iotools.energyplus_corrections import write_corrections
    before = convert_idf(CASE600, tmp_path / "600.json")
    effects = [("conductivity", "material:WALL FIBERGLASS QUILT", {"factor": 2.0}),
               ("solar_transmittance", "construction:DOUBLE CLEAR", {"tau": 0.6})]
    after = before
    for effect, target, values in effects:
        after = EFFECTS[effect].apply(after, target, values)
    out = tmp_path / "model_after.idf"
    result = write_corrections(before, after, [(e, t) for e, t, _ in effects], CASE600, out)
    assert result["not_written"] == []
    doc = idfkit.load_idf(str(out))
    # the Material itself conducts twice as much (Case 600's 0.040 W/m/K), the walls still built of it
    assert float(doc.getobject("MATERIAL", "WALL FIBERGLASS QUILT").conductivity) == pytest.approx(2 * 0.040)
    assert {doc.getobject("BUILDINGSURFACE:DETAILED", w).construction_name
            for w in ("EAST WALL", "WEST WALL", "NORTH WALL", "SOUTH WALL")} == {"LIGHT WALL"}
    # the Construction itself has the new glass; both windows are still of it
    assert {doc.getobject("FENESTRATIONSURFACE:DETAILED", w).construction_name
            for w in ("SOUTH WINDOW EAST", "SOUTH WINDOW WEST")} == {"DOUBLE CLEAR"}
    assert [c["object"] for c in result["changes"] if c["field"] != "(new object)"] == ["Material", "Construction"]
    again = convert_idf(out)
    for w in ("SOUTH WINDOW EAST", "SOUTH WINDOW WEST"):
        assert again.component(w).solar_transmittance == pytest.approx(0.6, abs=1e-5)
    R, R0 = (sum(t / m.conductivity for m, t in c.layers) for c in (again.component("EAST WALL"),
                                                                        before.component("EAST WALL")))
    quilt = next(t / m.conductivity for m, t in before.component("EAST WALL").layers
                 if m.name == "WALL FIBERGLASS QUILT")
    assert R == pytest.approx(R0 - quilt / 2)


# A change made to every member of a construction: the glass of both windows (0.5 where the file
# says 0.8), the insulation of all four walls (conducting twice what the file says).
CHANGED = {"glazing": ("solar_transmittance", {"tau": 0.5}), "walls": ("conductivity", {"factor": 2.0})}


@pytest.mark.slow
@pytest.mark.parametrize("construction", list(CHANGED))
def test_a_change_to_every_member_is_found_on_their_construction(tmp_path, testcell_data, weather, construction):
    """The diagnosis names the construction the changed components share, not one of them with a
    compensation elsewhere."""
    from nodeforce.diagnosis.loop import diagnose
    from nodeforce.ga.locate import Execution, SearchSettings
    from nodeforce.model.case import prepare_case
    from nodeforce.model.score import Objective
    from nodeforce.model.synth import pseudo_measurements
    from tests.conftest import SENSORS
    from tests.test_diagnose import NOISE, record
    b = parse_building(two_windows(testcell_data))
    effect, values = CHANGED[construction]
    truth = b
    for name in b.constructions[construction]:
        truth = EFFECTS[effect].apply(truth, name, values)
    measured = pseudo_measurements(truth, weather, record(12), SENSORS, noise_sd=NOISE, seed=5, history_days=7)
    report = diagnose(b, prepare_case(b, weather, measured).with_burn_in(1), tmp_path, Objective.of(b),
                      search=SearchSettings(seed=0), execution=Execution(workers=1)).to_json()
    assert [(e["effect"], e["target"]) for e in report["effects"]] == [(effect, f"construction:{construction}")]
    (name, truth_value), = values.items()
    found = report["effect"]["parameters"][name]
    assert abs(found["value"] - truth_value) <= max(0.05 * truth_value, 3 * found["std"])
    assert report["after"]["validation"]["rmse"] <= 1.5 * NOISE
