"""The records as the diagnosis reads them (`diagnose.loop.Windows`): given the file's numerical
error, every fit and choice reads the measurements corrected for it, and the metrics the
measurements as the user gave them (docs/model.md 5.8)."""
import numpy as np
import pytest

from nodeforce.diagnose.loop import Record, Windows
from nodeforce.model.case import prepare_case
from nodeforce.model.score import Objective
from nodeforce.model.synth import pseudo_measurements

from .conftest import SENSORS, record_times

AIR = 23


def test_the_choices_read_the_corrected_measurements_and_the_metrics_the_given_ones(testcell, weather):
    measurements = pseudo_measurements(testcell, weather, record_times(), SENSORS, history_days=0)
    case = prepare_case(testcell, weather, measurements).with_burn_in(1)
    objective = Objective.of(testcell)
    error = 0.2  # C at every measured node and step, a numerical error by hand
    ids = list(SENSORS)
    windows = Windows.of([Record(case)], objective, [(ids, np.full((len(case.times) - 1, len(ids)), error))])
    given = case.measured[1:, [AIR - 1]]
    scored = np.isfinite(windows.measured[0])
    k = windows.ks[0]

    # the file's run equal to the measurements as given: no error in the metrics, and in the
    # residuals the choices read the correction's 0.2 C at every scored step, J = n 0.04 C2
    metrics = windows.metrics(objective, [given])
    assert metrics["calibration"]["rmse"] == 0.0 and metrics["validation"]["rmse"] == 0.0
    assert windows.block_J([given]).sum() == pytest.approx(error ** 2 * scored[:k].sum())
    assert np.allclose(windows.measured[0][scored], given[scored] + error)
    # the calibrations the fits read and the other sensors the choice reads are corrected too
    calibration = windows.calibrations[0]
    assert np.allclose(calibration.measured[1:, AIR - 1], case.measured[1:k + 1, AIR - 1] + error)
    sensed = np.isfinite(windows.sensed[0])
    others = [i - 1 for i in windows.sensors[0]]
    assert np.allclose(windows.sensed[0][sensed], (case.measured[1:, others] + error)[sensed])
    # nothing measured is invented: a step without a measurement stays without
    assert np.array_equal(np.isnan(windows.cases[0].measured), np.isnan(case.measured))
