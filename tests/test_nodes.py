"""Nodes generated from the layers, node ids given by the tool, sensors named by position, and a
building that writes back the JSON it was read from."""
import copy
import json
from pathlib import Path

import jsonschema
import pytest

from nodeforce.model.building_file import load_building, parse_building
from nodeforce.model.discretise import generated_depths
from nodeforce.model.errors import InputError

from .test_zones import multizone_with_everything, two_zones

DATA = Path(__file__).parents[1] / "model" / "data"
SCHEMA = json.loads((DATA / "nodal-building.schema.json").read_text())


def test_generated_depths_by_hand():
    # IDEAS extwall_Ws inside-out: plaster 1 cm, brick 30 cm, old plaster 3 cm, EPS 8 cm, plaster 1 cm
    depths = generated_depths([0.01, 0.30, 0.03, 0.08, 0.01], max_spacing=0.05)
    expected = [0, 0.01, 0.06, 0.11, 0.16, 0.21, 0.26, 0.31, 0.34, 0.38, 0.42, 0.43]
    assert depths == pytest.approx(expected, abs=1e-12)
    # without the layer boundaries and a large spacing: the paper's two-node R2C component
    assert generated_depths([0.01, 0.30], 1.0, layer_boundaries=False) == pytest.approx([0, 0.31])
    # a sensor depth gets a node; one within a millimetre of an interface is that interface's node
    assert 0.2 in generated_depths([0.01, 0.30], 1.0, extra=[0.2])
    assert generated_depths([0.01, 0.30], 1.0, extra=[0.0105]) == pytest.approx([0, 0.01, 0.31])


def test_the_tool_numbers_components_then_zones():
    b = parse_building(two_zones())
    # each wall: 0.1 m at max_spacing 1 m -> two nodes; components first, then air and radiant
    assert b.component("wA").node_ids == (1, 2)
    assert b.component("wB").node_ids == (3, 4)
    assert (b.zone("A").air_node, b.zone("A").radiant_node) == (5, 6)
    assert (b.zone("B").air_node, b.zone("B").radiant_node) == (7, 8)
    assert b.node_names()[3] == "wB at 0.000 m" and b.node_names()[8] == "B radiant"


def test_ids_are_given_for_every_node_or_for_none():
    data = two_zones()
    data["zones"][0].update(air_node=5, radiant_node=6)
    with pytest.raises(InputError, match="give every node id"):
        parse_building(data, source="b.json")


def test_sensors_name_nodes_by_position():
    data = two_zones()
    data["components"][0]["nodes"] = {"max_spacing": 0.05}
    data["sensors"] = {"A_air": {"zone": "A"}, "wA_mid": {"component": "wA", "depth": 0.07},
                       "wA_out": {"component": "wA", "depth": 0.1}}
    b = parse_building(data)
    wall = b.component("wA")
    assert wall.depths == pytest.approx([0, 0.035, 0.07, 0.1])  # 0.07 cuts 0.1 m into 3.5 + 3 cm
    assert b.node_of("wA_mid") == wall.node_ids[2]
    assert b.node_of("wA_out") == wall.node_ids[-1]
    assert b.node_of("A_air") == b.zone("A").air_node
    assert b.node_of("T3") == 3 and b.node_of("nothing") is None
    assert jsonschema.Draft202012Validator(SCHEMA).is_valid(data)


@pytest.mark.parametrize("sensor,field", [
    ({"component": "wA", "depth": 0.05}, "sensors.s.depth"),  # explicit nodes at 0 and 0.1 only
    ({"component": "nowhere", "depth": 0.0}, "sensors.s.component"),
    ({"zone": "C"}, "sensors.s.zone"),
    ({"zone": "A", "component": "wA"}, "sensors.s"),
])
def test_a_sensor_that_names_no_node_is_refused(sensor, field):
    data = copy.deepcopy(json.loads((DATA / "testcell.json").read_text()))
    data["components"][0]["name"] = "wA"
    data["zones"][0]["name"] = "A"
    for c in data["components"]:
        for side in ("inside", "outside"):
            if c[side].get("zone") == "cell":
                c[side]["zone"] = "A"
    data["sensors"] = {"s": sensor}
    with pytest.raises(InputError) as caught:
        parse_building(data, source="b.json")
    assert str(caught.value).startswith(f"b.json: {field}:")


def test_a_building_writes_back_the_json_it_was_read_from(tmp_path):
    building = load_building(DATA / "testcell_miami.json")
    assert building.to_json() == json.loads((DATA / "testcell_miami.json").read_text())
    # a change is a new, validated building; the one it came from is untouched
    changed = building.edited(lambda d: d["zones"][0].update(internal_gain=50.0))
    assert changed.zone("cell").internal_gain == 50.0 and building.zone("cell").internal_gain == 0.0
    with pytest.raises(InputError):
        building.edited(lambda d: d["zones"][0].update(volume=-1.0))


def test_the_multizone_file_follows_the_schema():
    data = multizone_with_everything().to_json()
    assert list(jsonschema.Draft202012Validator(SCHEMA).iter_errors(data)) == []
