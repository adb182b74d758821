"""Pseudo-measurements: what the sensors of a building would read under a weather.

The paper verifies its method this way (Tables 2 and 3): measurements come from the model with
one sub-model disturbed, and the search must point at it. The simulation starts `history_days`
before the first time stamp, so the record begins from a state the building's own past made.
"""
import numpy as np
import pandas as pd

from .case import prepare_case
from .integrate import simulate
from .network import assemble


def pseudo_measurements(building, weather, times, nodes, noise_sd=0.0, seed=0, history_days=1):
    """Node temperatures (C) at `times`, as a measurements frame with columns `T<id>`.

    Parameters
    ----------
    building : Building, the "real" building
    weather : DataFrame from `read_weather`, covering the history and `times`
    times : uniform DatetimeIndex of the record
    nodes : node ids measured
    noise_sd : C, standard deviation of the Gaussian sensor noise added
    seed : seed of the noise
    history_days : days simulated before the record (after the model's own warm-up)
    """
    dt = times[1] - times[0]
    grid = pd.date_range(times[0] - pd.Timedelta(days=history_days), times[-1], freq=dt, name="time")
    empty = pd.DataFrame(index=grid)
    empty.attrs["source"] = "pseudo-measurements"
    case = prepare_case(building, weather, empty)
    T = simulate(building, assemble(building), case.U, case.dt, case.measured)
    record = T[len(grid) - len(times) - 1:, np.array(nodes) - 1]
    rng = np.random.default_rng(seed)
    record = record + rng.normal(0.0, noise_sd, record.shape) if noise_sd > 0 else record
    frame = pd.DataFrame(record, index=pd.DatetimeIndex(times, name="time"), columns=[f"T{i}" for i in nodes])
    frame.attrs["source"] = "pseudo-measurements"
    return frame
