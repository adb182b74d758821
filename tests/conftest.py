"""Shared fixtures: the reference test cell and a real-weather case (bundled Miami TMY2)."""
import copy
import json
from pathlib import Path

import pandas as pd
import pytest

from nodeforce.model.building import parse_building
from nodeforce.model.case import prepare_case
from nodeforce.model.synth import pseudo_measurements
from nodeforce.iotools.weather import read_weather

DATA = Path(__file__).parents[1] / "model" / "data"
SENSORS = (1, 7, 9, 16, 17, 23)


@pytest.fixture(scope="session")
def testcell_data():
    """The test cell placed at the bundled weather's site (Miami), as JSON data."""
    return json.loads((DATA / "testcell_miami.json").read_text())


@pytest.fixture(scope="session")
def testcell(testcell_data):
    return parse_building(testcell_data)


@pytest.fixture(scope="session")
def weather():
    return read_weather(DATA / "miami_tmy2.csv")


@pytest.fixture
def private_tmp(tmp_path, monkeypatch):
    """A temp directory of the test's own, for this process and every process it starts."""
    folder = tmp_path / "tmp"
    folder.mkdir()
    monkeypatch.setenv("TMPDIR", str(folder))
    monkeypatch.setattr("tempfile.tempdir", None)  # gettempdir() reads TMPDIR again; restored after
    return folder


def record_times(days=5, start="2001-06-10 00:00"):
    return pd.date_range(start, periods=days * 96 + 1, freq="15min", tz="-05:00", name="time")


@pytest.fixture(scope="session")
def real_case(testcell_data, testcell, weather):
    """5 days at 15 min in June; the paper's sensors measure a test cell whose door conducts
    0.78 W/m/K instead of 0.23 (paper's Table 2), so the model under test is wrong."""
    disturbed = copy.deepcopy(testcell_data)
    disturbed["materials"]["wood"]["conductivity"] = 0.78
    measurements = pseudo_measurements(parse_building(disturbed), weather, record_times(), SENSORS)
    return prepare_case(testcell, weather, measurements)


def _extracted():
    """Folders nodeforce made in the temp directory (extracted or built FMUs, simulations)."""
    import tempfile
    return {p.name for p in Path(tempfile.gettempdir()).glob("nodeforce_*")}


def pytest_sessionstart(session):
    session.config.nodeforce_extracted = _extracted()


def pytest_sessionfinish(session, exitstatus):
    """The whole suite leaves nothing it extracted in the temp directory."""
    left = sorted(_extracted() - session.config.nodeforce_extracted)
    if left:
        print(f"\nthe test suite left {len(left)} nodeforce folders in the temp directory: {left[:5]}")
        session.exitstatus = 1
