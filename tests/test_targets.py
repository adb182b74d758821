"""Effects on a construction or a material shared by several surfaces: the building file's
`constructions` group its components."""
import copy
from pathlib import Path

import pytest

from nodeforce.api import convert_idf
from nodeforce.model.building_file import parse_building
from nodeforce.model.errors import InputError

CASE600 = Path(__file__).resolve().parents[1] / "examples" / "bestest" / "case600.idf"


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
