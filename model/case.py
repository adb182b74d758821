"""A measured case on its simulation grid: the inputs and measurements every simulation reads."""
from dataclasses import dataclass

import numpy as np
import pandas as pd


@dataclass(frozen=True)
class Case:
    times: pd.DatetimeIndex  # t_0..t_N, uniform
    dt: float  # s
    input_names: tuple  # columns of U, as `model.network.input_names`
    U: np.ndarray  # (N_t+1, n_inputs) inputs at t_0..t_N
    measured: np.ndarray  # (N_t+1, N) node temperatures (C), NaN where not measured

    @property
    def measured_ids(self):
        """Ids of the nodes with at least one measurement."""
        return [i + 1 for i in np.flatnonzero(np.isfinite(self.measured).any(axis=0))]
