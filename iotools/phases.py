"""The phases of an experiment (heated at a set point, heat pulses, free float...): read and
check the phases CSV, `time,phase`, a phase starting at its time and lasting until the next
one starts (the last until the end of the record).

The loop scores every candidate on every phase (`diagnosis.loop`), so an effect that lowers the
total error while making one phase worse is seen.
"""
from dataclasses import dataclass

import pandas as pd

from nodeforce.model.errors import InputError
from .timetable import parse_times, check_increasing, one_line


@dataclass(frozen=True)
class Phase:
    name: str
    start: pd.Timestamp  # first time of the phase (inclusive)
    end: pd.Timestamp | None  # start of the next phase (exclusive), None for the last

    def mask(self, times):
        """Which of `times` (DatetimeIndex) fall in the phase."""
        inside = times >= self.start
        return inside & (times < self.end) if self.end is not None else inside


def read_phases(path):
    """The phases of the CSV at `path`, in time order; InputError naming the file, the column
    and the line for a missing column, a time without UTC offset, a time that does not
    increase, or an empty phase name."""
    try:
        frame = pd.read_csv(path, dtype=str, keep_default_na=False)
    except FileNotFoundError:
        raise InputError(path, "file", "not found") from None
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as error:
        raise InputError(path, "file", f"not a readable CSV: {one_line(error)}") from None
    for column in ("time", "phase"):
        if column not in frame.columns:
            raise InputError(path, column, "no such column (the header must read time,phase)")
    if frame.empty:
        raise InputError(path, "time", "no phase")
    times = parse_times(path, frame["time"])
    check_increasing(path, times, lambda i: f"line {i + 2}")
    names = frame["phase"].str.strip()
    if (names == "").any():
        raise InputError(path, "phase", f"line {int((names == '').to_numpy().argmax()) + 2}: empty phase name")
    ends = list(times[1:]) + [None]
    return tuple(Phase(name, start, end) for name, start, end in zip(names, times, ends))
