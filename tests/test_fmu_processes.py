"""The search through either FMU kind gives the same answer, and worker processes that ran FMUs
end cleanly (glibc reported corrupted memory at their exit in about half of the runs)."""
import copy
import json
import subprocess
import sys

import pytest

from nodeforce.cli import main
from nodeforce.model.building_file import parse_building
from nodeforce.model.synth import pseudo_measurements
from tests.conftest import DATA, SENSORS, record_times


@pytest.fixture(scope="module")
def files(tmp_path_factory, testcell_data, weather):
    """Two days measured on a test cell whose door conducts 0.78 W/m/K, not the file's 0.23."""
    d = tmp_path_factory.mktemp("processes")
    building = d / "cell.json"
    building.write_text(json.dumps(testcell_data))
    disturbed = copy.deepcopy(testcell_data)
    disturbed["materials"]["wood"]["conductivity"] = 0.78
    measured = d / "measured.csv"
    pseudo_measurements(parse_building(disturbed), weather, record_times(days=2), SENSORS).to_csv(
        measured, date_format="%Y-%m-%dT%H:%M:%S%z")
    # the record starts in the periodic regime of its first day (no history): the model is told so
    return ["locate", str(building), "--weather", str(DATA / "miami_tmy2.csv"), "--measurements", str(measured),
            "--nodes", "1,7,9", "--history-days", "0"]


def test_locate_gives_the_same_answer_through_either_fmu(files, tmp_path, capsys):
    results = {}
    for kind in ("python", "standalone"):
        assert main(files + ["-o", str(tmp_path / kind), "--fmu", kind, "--workers", "1"]) == 0
        results[kind] = json.loads((tmp_path / kind / "locate.json").read_text())
    python, standalone = results["python"], results["standalone"]
    assert python["best_nodes"] == standalone["best_nodes"] == [7]
    for node, J in python["node_scores"].items():
        assert abs(standalone["node_scores"][node] - J) <= 1e-9 * max(1.0, J)


@pytest.mark.slow  # processes, a cluster or a whole diagnosis: not in `make check`
def test_locate_with_two_workers_ends_cleanly_ten_times(files, tmp_path):
    for run in range(10):
        done = subprocess.run([sys.executable, "-m", "nodeforce", *files, "-o", str(tmp_path / str(run)),
                               "--workers", "2"], capture_output=True, text=True, timeout=300)
        assert done.returncode == 0, done.stderr
        assert "corrupted" not in done.stderr and "free()" not in done.stderr, f"run {run}:\n{done.stderr}"
