"""ASHRAE 140's free-float cases (examples/bestest, `make bestest`) through `nodeforce convert`
and the direct model over the Denver year, against the reference programs' range (ASHRAE
140-2020, Tables B8-5a, b, c). docs/model.md section 10 gives the table."""
import sys
from pathlib import Path

import idfkit
import pytest

from nodeforce.api import convert_idf
from nodeforce.iotools.typical_year import convert_typical_year
from nodeforce.iotools.weather import read_weather
from nodeforce.model.case import simulate_building

BESTEST = Path(__file__).resolve().parents[1] / "examples" / "bestest"
sys.path.insert(0, str(BESTEST))
import cases  # noqa: E402
from run import REFERENCE  # noqa: E402


@pytest.fixture(scope="module")
def denver(tmp_path_factory):
    path = tmp_path_factory.mktemp("bestest") / "weather.csv"
    convert_typical_year(BESTEST / "data" / "725650TYCST.epw", path, year=2017)
    return read_weather(path)


@pytest.mark.slow
@pytest.mark.parametrize("case", ["600FF", "650FF", "900FF", "950FF", "680FF", "980FF"])
def test_free_float_case_against_ashrae_140(case, denver, tmp_path):
    path = tmp_path / f"{case}.idf"
    idfkit.save_idf(cases.CASES[case](), str(path))
    building = convert_idf(path)
    T = simulate_building(building, denver)[f"T{building.zones[0].air_node}"]
    figures = {"min": T.min(), "max": T.max(), "mean": T.mean()}
    for key, value in figures.items():
        low, high = REFERENCE[case][key]
        assert low <= value <= high, f"{case} {key} {value:.2f} outside {low}..{high}"
