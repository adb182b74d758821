"""Measured node temperatures: read and check the measurements CSV (INTERFACE.md, Files).

Measurements are never changed: an empty cell stays missing (NaN) and no value is interpolated or
filled; the model handles a missing measurement where it uses one (PHYSICS.md section 5).
"""

import re

from nodeforce.model.errors import InputError
from .timetable import check_celsius, read_time_table

_NODE_COLUMN = re.compile(r"T([1-9][0-9]*)")


def read_measurements(path):
    """Read and check a measurements CSV.

    Parameters
    ----------
    path : str or Path
        CSV with a `time` column (ISO 8601 with UTC offset, strictly increasing) and one column
        `T<id>` per measured node (degrees C, id a positive integer without leading zeros, e.g.
        `T23`); an empty cell is a missing value.

    Returns
    -------
    pandas.DataFrame
        Float columns `T<id>`, degrees C, in file order, indexed by a tz-aware DatetimeIndex
        named "time"; missing values are NaN. `attrs["source"]` is the path.

    Raises
    ------
    InputError
        Naming the file and the column: the checks of `iotools.timetable.read_time_table` (time
        column, times, non-numeric cells), a column not named `T<id>`, no measured column,
        kelvin-looking temperatures (median above `iotools.timetable.KELVIN_MEDIAN`).
    """
    frame = read_time_table(path)
    for name in frame.columns:
        if not _NODE_COLUMN.fullmatch(name):
            raise InputError(path, name, "measurement columns are named T<node id>, a positive integer without leading zeros, e.g. T23")
    if frame.columns.empty:
        raise InputError(path, "T<id>", "no measured node column besides time")
    check_celsius(frame, frame.columns)
    return frame

