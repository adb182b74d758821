"""examples/driver.py, a user's own PyGAD search over the FMU, runs on a small budget and finds
the fault the demo's measurements carry (a ground coupling under the floor), as locate does."""
import subprocess
import sys
from pathlib import Path

import pytest

DRIVER = Path(__file__).parents[1] / "examples" / "driver.py"


@pytest.mark.slow
def test_driver_finds_the_floor_and_agrees_with_locate(tmp_path):
    run = subprocess.run([sys.executable, str(DRIVER), "--population", "10", "--generations", "12", "--seed", "2"],
                         capture_output=True, text=True, cwd=tmp_path, timeout=600)
    assert run.returncode == 0, run.stdout + run.stderr
    lines = run.stdout.splitlines()
    assert sum(line.startswith("generation") for line in lines) == 12  # the callback, once a generation
    assert "agree: both force floor" in lines[-1]
