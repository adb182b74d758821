"""The other sensors' weights in the choice among explanations of the air
(`diagnosis.windows.Windows.sensor_weights`): sigma^2 over what the model already misses at each,
checked against a sensor offset by a known amount."""
import numpy as np

from nodeforce.diagnosis.loop import Model
from nodeforce.diagnosis.policy import Policy
from nodeforce.diagnosis.windows import Record, Windows
from nodeforce.model.case import prepare_case
from nodeforce.model.score import Objective
from nodeforce.model.synth import pseudo_measurements

from .conftest import SENSORS, record_times


def test_a_sensor_the_model_misses_by_a_kelvin_weighs_sigma_squared_and_one_it_follows_fully(testcell, weather):
    # the model's own record, noise-free, steady from its first day: it follows every sensor but
    # the one offset by 1 K, whose mean squared residual is then 1 K2
    measurements = pseudo_measurements(testcell, weather, record_times(), SENSORS, history_days=0)
    offset = "T9"  # the roof's inner surface
    measurements[offset] = measurements[offset] + 1.0
    case = prepare_case(testcell, weather, measurements).with_burn_in(1)
    objective = Objective.of(testcell)
    windows = Windows.of([Record(case)], objective, Policy())
    assert windows.sensors == [[1, 7, 9, 16, 17]]
    sigma = 0.1
    (weights,) = windows.sensor_weights([windows.sensed_by(Model(testcell, [], {}, [None]))], sigma)
    roof = windows.sensors[0].index(9)
    assert abs(weights[roof] - sigma ** 2 / 1.0) < 0.1 * sigma ** 2
    assert np.all(np.delete(weights, roof) == 1.0)


def test_a_sensor_a_candidate_mends_counts_fully_and_one_none_mends_stays_discounted(testcell, weather):
    # the same record; the roof's surface 1 K off under the model as written. A candidate that
    # follows it (its runs the measurements themselves, to the noise) makes it a sensor like the
    # others: its misfit was the model's fault, not the sensor's. One that mends nothing leaves
    # the weight sigma^2 / 1 K2
    measurements = pseudo_measurements(testcell, weather, record_times(), SENSORS, history_days=0)
    measurements["T9"] = measurements["T9"] + 1.0
    case = prepare_case(testcell, weather, measurements).with_burn_in(1)
    windows = Windows.of([Record(case)], Objective.of(testcell), Policy())
    sigma = 0.1
    model = windows.sensed_by(Model(testcell, [], {}, [None]))
    follows = [np.nan_to_num(windows.sensed[0], nan=0.0) + 0.5 * sigma]  # within the noise everywhere: weight 1
    roof = windows.sensors[0].index(9)
    (alone,) = windows.sensor_weights([model], sigma)
    (mended,) = windows.sensor_weights([model, follows], sigma)
    (unmended,) = windows.sensor_weights([model, model], sigma)
    assert abs(alone[roof] - sigma ** 2) < 0.1 * sigma ** 2
    assert mended[roof] == 1.0 and np.all(mended == 1.0)
    assert np.array_equal(unmended, alone)
