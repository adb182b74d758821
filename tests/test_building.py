"""A building file with a mistake is refused with the file, the field and the problem named."""
import copy
import json
from pathlib import Path

import pytest

from nodeforce.model.building_file import load_building, parse_building
from nodeforce.model.errors import InputError

TESTCELL = json.loads((Path(__file__).parents[1] / "model" / "data" / "testcell.json").read_text())


def refused(mutate):
    data = copy.deepcopy(TESTCELL)
    mutate(data)
    with pytest.raises(InputError) as e:
        parse_building(data, source="cell.json")
    assert str(e.value).startswith("cell.json: ")
    assert "\n" not in str(e.value)
    return e.value


def test_reference_test_cell_loads_with_23_nodes():
    b = parse_building(TESTCELL)
    assert b.n_nodes == 23
    assert [c.name for c in b.exterior_components] == [
        "east_wall", "west_wall", "south_wall", "door", "roof", "north_wall", "window"]


def test_node_ids_with_a_gap_are_refused():
    def gap(d):
        d["zones"][0]["air_node"] = 24
    e = refused(gap)
    assert e.field == "nodes" and "1..23" in e.problem and "23" in e.problem


def test_duplicated_node_id_is_refused():
    e = refused(lambda d: d["components"][1]["nodes"][0].update(id=1))
    assert e.field == "nodes" and "twice" in e.problem


def test_node_depth_outside_its_component_is_refused():
    e = refused(lambda d: d["components"][3]["nodes"][1].update(depth=0.05))
    assert e.field == "components[3].nodes[1].depth" and "outside the component" in e.problem


def test_unknown_material_is_refused():
    e = refused(lambda d: d["components"][4]["layers"][1].__setitem__(0, "unobtainium"))
    assert e.field == "components[4].layers[1]" and "unobtainium" in e.problem


def test_node_depths_must_increase():
    def swap(d):
        nodes = d["components"][7]["nodes"]
        nodes[1]["depth"], nodes[2]["depth"] = nodes[2]["depth"], nodes[1]["depth"]
    e = refused(swap)
    assert e.field == "components[7].nodes"


def test_wrong_format_and_bad_numbers_are_refused():
    assert refused(lambda d: d.update(format="other/2")).field == "format"
    assert refused(lambda d: d["components"][0].update(area=-1)).field == "components[0].area"
    assert refused(lambda d: d["zones"][0].update(volume="big")).field == "zones[0].volume"
    assert refused(lambda d: d["materials"]["wood"].update(conductivity=0)).field == "materials.wood.conductivity"
    e = refused(lambda d: d["components"][0]["outside"].update(type="garden"))
    assert e.field == "components[0].outside.type"


def test_unknown_zone_and_glazing_target_are_refused():
    assert refused(lambda d: d["components"][0]["inside"].update(zone="attic")).field == "components[0].inside.zone"
    e = refused(lambda d: d["components"][6].update(transmitted_solar_to="carpet"))
    assert e.field == "components[6].transmitted_solar_to"


def test_file_errors_name_the_file(tmp_path):
    with pytest.raises(InputError, match="not found"):
        load_building(tmp_path / "missing.json")
    bad = tmp_path / "bad.json"
    bad.write_text("{ not json")
    with pytest.raises(InputError) as e:
        load_building(bad)
    assert str(bad) in str(e.value) and "JSON" in str(e.value)


def test_a_misspelt_field_is_refused_not_ignored(tmp_path):
    data = copy.deepcopy(TESTCELL)
    data["components"][3]["conductivty_factor"] = 2.0
    path = tmp_path / "typo.json"
    path.write_text(json.dumps(data))
    with pytest.raises(InputError) as e:
        load_building(path)
    assert e.value.field == "components[3]" and "conductivty_factor" in e.value.problem
