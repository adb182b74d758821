"""Pseudo-measurements: what the sensors of a building would read under a weather.

The paper verifies its method this way (Tables 2 and 3): measurements come from the model with
one sub-model disturbed, and the search must point at it.

The "real" building starts in the periodic regime of its first day: the model's own warm-up
(docs/model.md section 5) carried on for `spinup_days` passes, as building simulation tools
precondition a run. A record that starts there is a fixed point of the warm-up, so a model that
is right everywhere reproduces it exactly, and what remains comes from the disturbed sub-model.
`history_days` of real weather may follow before the record, for a building whose past was not
periodic (the model under test then starts from what its measurements and warm-up can tell).
"""
import numpy as np
import pandas as pd

from .case import prepare_case
from .integrate import simulate
from .network import assemble


def pseudo_measurements(building, weather, times, nodes, noise_sd=0.0, seed=0, history_days=0,
                        spinup_days=365, decomposition="erbs"):
    """Node temperatures (C) at `times`, as a measurements frame with columns `T<id>`.

    Parameters
    ----------
    building : Building, the "real" building
    weather : DataFrame from `read_weather`, covering the history and `times`
    times : uniform DatetimeIndex of the record
    nodes : node ids measured
    noise_sd : C, standard deviation of the Gaussian sensor noise added
    seed : seed of the noise
    history_days : days of real weather simulated before the record
    spinup_days : passes over the first simulated day that make the start periodic
    decomposition : pvlib's split of ghi where the weather has it alone (`model.case.prepare_case`)
    """
    dt = times[1] - times[0]
    grid = pd.date_range(times[0] - pd.Timedelta(days=history_days), times[-1], freq=dt, name="time")
    empty = pd.DataFrame(index=grid)
    empty.attrs["source"] = "pseudo-measurements"
    case = prepare_case(building, weather, empty, decomposition)
    T = simulate(case.building, assemble(case.building), case.U, case.dt, case.measured,
                 warmup_days=spinup_days, include_start=True, substeps=case.substeps)
    record = T[len(grid) - len(times):, np.array(nodes) - 1]
    rng = np.random.default_rng(seed)
    record = record + rng.normal(0.0, noise_sd, record.shape) if noise_sd > 0 else record
    frame = pd.DataFrame(record, index=pd.DatetimeIndex(times, name="time"), columns=[f"T{i}" for i in nodes])
    frame.attrs["source"] = "pseudo-measurements"
    return frame
