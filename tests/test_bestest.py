"""ASHRAE 140's free-float cases (examples/bestest, `make bestest`) through `nodeforce convert`
and the direct model over the Denver year the repository carries, against the reference
programs' range (ASHRAE 140-2020, Tables B8-5a, b, c). docs/model.md section 10 gives the table."""
import sys
from pathlib import Path

import idfkit
import pandas as pd
import pytest

from nodeforce.api import convert_idf
from nodeforce.iotools.weather import read_weather
from nodeforce.model.case import simulate_building
from nodeforce.model.weather import weather_on_grid

BESTEST = Path(__file__).resolve().parents[1] / "examples" / "bestest"
sys.path.insert(0, str(BESTEST))
import cases  # noqa: E402
from run import REFERENCE, STEP, WEATHER, YEAR, hourly, in_range  # noqa: E402


@pytest.fixture(scope="module")
def denver():
    return read_weather(WEATHER, year=YEAR)


@pytest.mark.slow
@pytest.mark.parametrize("case", ["600FF", "650FF", "900FF", "950FF", "680FF", "980FF"])
def test_free_float_case_against_ashrae_140(case, denver, tmp_path):
    path = tmp_path / f"{case}.idf"
    idfkit.save_idf(cases.CASES[case](), str(path))
    building = convert_idf(path)
    grid = pd.date_range(denver.index[0], denver.index[-1], freq=pd.Timedelta(seconds=STEP))
    T = hourly(simulate_building(building, weather_on_grid(denver, grid))[f"T{building.zones[0].air_node}"])
    figures = {"min": T.min(), "max": T.max(), "mean": T.mean()}
    for key, value in figures.items():
        low, high = REFERENCE[case][key]
        assert in_range(value, low, high), f"{case} {key} {value:.2f} outside {low}..{high}"


def test_the_carried_weather_is_the_standards_denver_year():
    weather = read_weather(WEATHER)
    assert weather.attrs["typical_year"] and len(weather) == 2 * 8760 - 1  # every half hour
    assert weather.index[0].utcoffset().total_seconds() == -7 * 3600  # Mountain standard time
    # Denver's typical year: an annual mean air near 10 C and a few hundred W/m2 of noon sun
    assert 8.0 < weather["T_out"].mean() < 12.0 and 800 < weather["ghi"].max() < 1200


def test_the_carried_case_600_building_file_is_what_convert_makes_of_its_idf(monkeypatch):
    """examples/bestest/case600.json, which the docs simulate, stays `nodeforce convert`'s, run
    from the repository's root as its README says."""
    import json
    monkeypatch.chdir(BESTEST.parents[1])
    made, carried = convert_idf(Path("examples/bestest/case600.idf")).data, json.loads((BESTEST / "case600.json").read_text())
    # the file names its IDF from its own folder
    assert (BESTEST / carried.pop("energyplus")["idf"]).resolve() == Path(made.pop("energyplus")["idf"]).resolve()
    assert json.loads(json.dumps(made)) == carried  # as written: tuples are lists
