"""Measured temperatures: read and check the measurements CSV (docs/guide.md, Measurements).

Measurements are never changed: an empty cell stays missing (NaN) and no value is interpolated or
filled; the model handles a missing measurement where it uses one (docs/model.md section 5).
"""

from nodeforce.model.building import NODE_COLUMN
from nodeforce.model.errors import InputError
from nodeforce.model.units import check_celsius
from .timetable import read_time_table


def read_measurements(path):
    """Read and check a measurements CSV.

    Parameters
    ----------
    path : str or Path
        CSV with a `time` column (ISO 8601 with UTC offset, strictly increasing) and one column
        per measured temperature (degrees C): `T<id>` for node id (e.g. `T23`), or another name,
        which the building resolves to a node (`nodeforce.model.case.measured_matrix`, where an
        unknown name is refused) or to a heat flux sensor on a face (W/m2,
        `nodeforce.model.case.measured_fluxes`). An empty cell is a missing value.

    Returns
    -------
    pandas.DataFrame
        Float columns, degrees C, in file order, indexed by a tz-aware DatetimeIndex named
        "time"; missing values are NaN. `attrs["source"]` is the path.

    Raises
    ------
    InputError
        Naming the file and the column: the checks of `iotools.timetable.read_time_table` (time
        column, times, non-numeric cells), no measured column, kelvin-looking temperatures
        (median above `model.units.KELVIN_MEDIAN`) in a `T<id>` column. Another name is
        checked once the building has said it is a sensor's (`model.case.measured_matrix`): a
        column that names no node (a heat power put here) is told so, not that it looks like kelvin.
    """
    frame = read_time_table(path)
    if frame.columns.empty:
        raise InputError(path, "T<id>", "no measured column besides time")
    check_celsius(frame, [c for c in frame.columns if NODE_COLUMN.match(str(c))])
    return frame
