"""`nodeforce convert` on every reference and prototype IDF the `energyplus` extra ships
(pyenergyplus-lbnl, benchmarks/convert_corpus.py): each within a time limit, no traceback, and
either a building file that simulates free-floating or a one-line refusal naming the file and the
physics it cannot hold.
EnergyPlus is never needed for the tests: without the extra this module is skipped, and the
self-made IDFs of tests/test_energyplus_reading.py still run."""
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

pytest.importorskip("pyenergyplus")
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
from convert_corpus import convert_one, shipped_idfs  # noqa: E402

pytestmark = pytest.mark.slow
TIME_LIMIT = 60.0  # s a file, the command's start included, on a shared 2-core machine
IDFS = shipped_idfs()


def test_the_extra_ships_the_reference_buildings():
    assert len(IDFS) >= 30


@pytest.mark.parametrize("idf", IDFS, ids=[p.stem for p in IDFS])
def test_each_shipped_idf_converts_or_is_refused_in_one_line(idf, tmp_path):
    status, seconds, data, stderr = convert_one(idf, tmp_path / "b.json", TIME_LIMIT)
    assert status in ("converted", "refused"), (status, stderr)
    assert "Traceback" not in stderr
    if status == "converted":
        assert data["zones"] and data["components"]
        assert all("\n" not in line for line in data["not_modelled"])
        # and it simulates free-floating: a day of a winter's sun and cold, every zone's air finite
        from nodeforce.iotools.weather import read_weather
        from nodeforce.model.building_file import parse_building
        from nodeforce.model.case import simulate_building
        times = pd.date_range("2017-01-15", periods=24 * 4 + 1, freq="15min", tz="UTC")
        hour = times.hour + times.minute / 60
        sun = np.clip(np.sin(np.pi * (hour - 13) / 10), 0, None)  # a day of sun around 20:00 UTC (US noon)
        path = tmp_path / "w.csv"
        pd.DataFrame({"time": [t.isoformat() for t in times], "T_out": -5.0, "ghi": 500 * sun, "dni": 700 * sun,
                      "dhi": 100 * sun, "wind_speed": 4.0, "wind_direction": 200.0}).to_csv(path, index=False)
        b = parse_building(data, source=str(tmp_path / "b.json"))
        T = simulate_building(b, read_weather(path))
        assert np.isfinite(np.array([T[f"T{z.air_node}"].to_numpy() for z in b.zones])).all()
    else:
        (line,) = stderr.strip().splitlines()
        assert str(idf) in line and ", field " in line
