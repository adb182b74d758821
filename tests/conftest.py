"""Shared fixtures: the reference test cell and a real-weather case (bundled Miami TMY2)."""
import copy
import json
import os
import shutil
import tempfile
from pathlib import Path

import pandas as pd
import pytest

from nodeforce.model.building_file import load_building, parse_building
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


@pytest.fixture(scope="session")
def twinhouse():
    """The Twin House (examples/twinhouse_n2) as its file declares it: a large network (281 nodes)
    with shading columns and coefficients that follow the state (TARP inside, its windows' panes
    and argon gaps, DOE-2 and the long-wave outside), which both FMUs step."""
    return load_building(Path(__file__).parents[1] / "examples" / "twinhouse_n2" / "building.json")


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


def _extracted(root):
    """Folders nodeforce made in the temp directory `root` of a test process and of the
    pytest-xdist workers it started (extracted or built FMUs, simulations)."""
    root = Path(root)
    return sorted(str(p.relative_to(root)) for pattern in ("nodeforce_*", "pytest-nodeforce-*/nodeforce_*")
                  for p in root.glob(pattern))


def pytest_configure(config):
    """Each test process gets a temp directory of its own (a pytest-xdist worker one inside its
    controller's), and so do the processes it starts, through TMPDIR: the check below then sees
    only what this run's tests left, not another run's folders."""
    config.nodeforce_tmp = tempfile.mkdtemp(prefix="pytest-nodeforce-")
    os.environ["TMPDIR"] = config.nodeforce_tmp
    tempfile.tempdir = None  # gettempdir() reads TMPDIR again


def pytest_sessionfinish(session, exitstatus):
    """The whole suite leaves nothing it extracted in the temp directory (checked by the process
    that started the run, after its workers have finished)."""
    if os.environ.get("PYTEST_XDIST_WORKER"):
        return
    left = _extracted(session.config.nodeforce_tmp)
    if left:
        print(f"\nthe test suite left {len(left)} nodeforce folders in the temp directory: {left[:5]}")
        session.exitstatus = 1


def pytest_unconfigure(config):
    if not os.environ.get("PYTEST_XDIST_WORKER"):  # a worker's folder is its controller's to check
        shutil.rmtree(config.nodeforce_tmp, ignore_errors=True)
