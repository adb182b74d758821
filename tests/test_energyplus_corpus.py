"""`nodeforce convert` on every reference and prototype IDF the `energyplus` extra ships
(pyenergyplus-lbnl, benchmarks/convert_corpus.py): each within a time limit, no traceback, and
either a building file or a one-line refusal naming the file and the physics it cannot hold.
EnergyPlus is never needed for the tests: without the extra this module is skipped, and the
self-made IDFs of tests/test_energyplus_reading.py still run."""
import json
import sys
from pathlib import Path

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
        json.dumps(data)
    else:
        (line,) = stderr.strip().splitlines()
        assert str(idf) in line and ", field " in line
