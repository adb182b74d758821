"""examples/calibrate_fmu.py: another tool (scipy's least squares over FMPy) calibrates the door's
conductivity factor through the FMU's parameters alone, and finds what `nodeforce diagnose`
finds on the same record."""
import json
import subprocess
import sys
from pathlib import Path

import pytest

from nodeforce.cli import main

pytestmark = pytest.mark.slow  # a diagnosis and an outside calibration

EXAMPLE = Path(__file__).parents[1] / "examples" / "calibrate_fmu.py"
DATA = Path(__file__).parents[1] / "model" / "data"


def outside(folder, *options):
    done = subprocess.run([sys.executable, str(EXAMPLE), "-o", str(folder), *options], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return json.loads((folder / "estimate.json").read_text())


def test_an_outside_calibration_through_the_fmu_finds_what_diagnose_finds(tmp_path):
    outside(tmp_path)  # the record, the FMU and the inputs the diagnosis reads too
    assert main(["diagnose", str(DATA / "testcell_miami.json"), "--weather", str(DATA / "miami_tmy2.csv"),
                 "--measurements", str(tmp_path / "measurements.csv"), "--burn-in-days", "1",
                 "-o", str(tmp_path / "diagnosis")]) == 0
    report = json.loads((tmp_path / "diagnosis" / "report.json").read_text())
    assert (report["effect"]["effect"], report["effect"]["target"]) == ("conductivity", "door")
    found = report["effect"]["parameters"]["factor"]
    # on the record the diagnosis calibrated on (its calibration window), within its uncertainty
    same = outside(tmp_path, "--fit-until", report["period"]["calibration"][1])
    assert abs(same["value"] - found["value"]) <= found["std"]
    # both near the real door's 0.78 / 0.23, within the bounds the FMU declares
    for estimate in (same, found):
        assert abs(estimate["value"] - 0.78 / 0.23) <= 3 * estimate["std"]
    assert same["bounds"][0] < same["value"] < same["bounds"][1]
