"""Nothing is left behind: a search and a diagnosis, in worker processes too, remove every FMU
they extracted and every temporary folder they made, when they succeed and when they fail."""
import os

import pandas as pd
import pytest

from nodeforce.diagnosis.loop import diagnose
from nodeforce.ga.locate import Execution, SearchSettings
from nodeforce.model.case import prepare_case
from nodeforce.model.errors import InputError
from nodeforce.model.score import Objective
from nodeforce.model.synth import pseudo_measurements
from tests.conftest import SENSORS

pytestmark = pytest.mark.slow


def test_a_diagnosis_with_workers_leaves_the_temp_directory_empty(tmp_path, private_tmp, testcell, weather):
    times = pd.date_range("2001-06-10 00:00", periods=6 * 96 + 1, freq="15min", tz="-05:00", name="time")
    measurements = pseudo_measurements(testcell, weather, times, SENSORS, noise_sd=0.1, seed=1)
    case = prepare_case(testcell, weather, measurements).with_burn_in(1)
    out = tmp_path / "out"
    out.mkdir()
    diagnose(testcell, case, out, Objective.of(testcell), search=SearchSettings(population=8, generations=4),
             execution=Execution(workers=2))
    assert os.listdir(private_tmp) == []
    # and when the run fails half-way (no validation window left), too
    with pytest.raises(InputError):
        diagnose(testcell, case.window(0, 2 * 96 + 10), out, Objective.of(testcell),
                 execution=Execution(workers=2))
    assert os.listdir(private_tmp) == []
