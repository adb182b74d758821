"""CSV time tables: a `time` column (ISO 8601 with UTC offset) and numeric columns, read and written.

The weather and measurement readers are built on `read_time_table`; the typical-year converter and
`nodeforce table` write with `write_time_table`.
"""

import csv
import gzip
import lzma
import re
from pathlib import Path

import numpy as np
import pandas as pd

from nodeforce.model.errors import InputError
from nodeforce.model.weather import utc_microseconds

# The offset must follow a clock time, so a bare date's "-01" is not taken for one.
_OFFSET = re.compile(r"[T ][\d:.,]+(Z|[+-]\d{2}(?::?\d{2})?)$")


def read_time_table(path):
    """Read a CSV with a `time` column and numeric columns, checked, one row per instant.

    Parameters
    ----------
    path : str or Path
        CSV file. `time` holds ISO 8601 times with a UTC offset (`Z` or `+hh:mm`); the other cells
        are numbers. An empty cell is a missing value, and so are pandas' usual missing markers
        (NA, NaN, N/A, null, #N/A): they say "missing" explicitly, so reading them so invents nothing.

    Returns
    -------
    pandas.DataFrame
        Float columns as in the file (header names stripped of blanks), indexed by a tz-aware
        DatetimeIndex named "time": in the file's UTC offset if there is only one, else in UTC.
        Missing cells are NaN. `attrs["source"]` is the path, for later error messages.

    Raises
    ------
    InputError
        Unreadable file, no or duplicated header names, no `time` column, no rows, a time that is
        not ISO 8601 or has no UTC offset, times not strictly increasing, a non-numeric cell.
    """
    source = str(path)
    header = _header(source)
    if "time" not in header:
        raise InputError(source, "time", "no time column (the header must name one 'time')")
    try:
        raw = pd.read_csv(path, dtype=str, skipinitialspace=True, index_col=False, encoding="utf-8-sig")
    except (pd.errors.ParserError, UnicodeDecodeError, ValueError) as error:
        raise InputError(source, "file", f"not a readable CSV: {one_line(error)}") from None
    raw.columns = header
    if raw.empty:
        raise InputError(source, "time", "no data rows")
    times = parse_times(source, raw["time"])
    check_increasing(source, times, where=lambda i: f"line {i + 2}")
    frame = pd.DataFrame(
        {name: _numeric(source, name, raw[name]) for name in header if name != "time"},
        index=times,
    )
    frame.attrs["source"] = source
    return frame


def write_time_table(frame, path, float_format=None):
    """Write a frame as a CSV time table: ISO 8601 times with offset, empty cells for NaN.

    Parameters
    ----------
    frame : pandas.DataFrame
        Indexed by tz-aware time; numeric columns, written in their order.
    path : str or Path
        CSV file to write; its folder is made if absent.
    float_format : str, optional
        printf format of the numbers; by default each is written in full (its shortest exact
        decimal form), so nothing is rounded.
    """
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    out = frame.copy()
    out.index = pd.Index([t.isoformat() for t in frame.index], name="time")
    out.to_csv(path, float_format=float_format, lineterminator="\n")


def check_increasing(source, times, where):
    """InputError naming `where(i)` (e.g. "line 12") at the first time that does not increase."""
    steps = np.diff(utc_microseconds(times))
    if (steps <= 0).any():
        i = int(np.flatnonzero(steps <= 0)[0]) + 1
        what = "repeats the previous time" if steps[i - 1] == 0 else "is before the previous time"
        raise InputError(source, "time", f"{where(i)}: {times[i].isoformat()} {what}; times must increase")


def instant(option, text):
    """The tz-aware Timestamp of an ISO 8601 time given with its UTC offset; InputError naming
    `option` (e.g. "--origin") otherwise."""
    try:
        time = pd.Timestamp(text)
    except ValueError:
        raise InputError(option, text, "not an ISO 8601 time") from None
    if time.tzinfo is None:
        raise InputError(option, text, "needs a UTC offset, e.g. 2013-01-01T00:00+01:00")
    return time


#: Compressed text files read as they are, by the suffix of their name: nothing decompressed is
#: written beside them.
_OPENERS = {".gz": gzip.open, ".xz": lzma.open}


def read_text(path):
    """The text of a file, UTF-8 (a byte-order mark dropped), decompressed first when its name ends
    in `.gz` (gzip) or `.xz` (xz).

    Raises
    ------
    InputError
        One line naming the file: not found, unreadable, not valid compressed data, not text.
    """
    opener = _OPENERS.get(Path(path).suffix.lower(), open)
    try:
        with opener(path, "rt", encoding="utf-8-sig") as handle:
            return handle.read()
    except FileNotFoundError:
        raise InputError(path, "file", "not found") from None
    except (OSError, EOFError, lzma.LZMAError, UnicodeDecodeError) as error:
        raise InputError(path, "file", one_line(error)) from None


def uncompressed_name(path):
    """A file's name without the `.gz` or `.xz` that `read_text` decompresses."""
    path = Path(path)
    return path.stem if path.suffix.lower() in _OPENERS else path.name


def one_line(error):
    """An exception's message on one line."""
    return " ".join(str(error).split())


def _header(source):
    try:
        with open(source, newline="", encoding="utf-8-sig") as handle:
            header = next(csv.reader(handle), None)
    except (OSError, UnicodeDecodeError) as error:
        raise InputError(source, "file", one_line(error)) from None
    if not header:
        raise InputError(source, "file", "empty file (no header line)")
    header = [name.strip() for name in header]
    check_column_names(source, header, "header")
    return header


def check_column_names(source, names, field):
    """InputError naming `source` where a column of `names` (given in `field`, e.g. "header")
    has no name or shares its name with another."""
    seen = set()
    for name in names:
        if not name:
            raise InputError(source, field, "a column has no name")
        if name in seen:
            raise InputError(source, name, f"two columns have this name in the {field}")
        seen.add(name)


def parse_times(source, text):
    """The DatetimeIndex of a time column of ISO 8601 texts with UTC offsets; InputError naming
    `source` and the line of the first empty, offset-less or unreadable time."""
    text = text.str.strip()
    empty = text.isna() | (text == "")
    if empty.any():
        raise InputError(source, "time", f"line {int(np.flatnonzero(empty)[0]) + 2}: empty time")
    offsets = text.str.extract(_OFFSET)[0]
    naive = offsets.isna()
    if naive.any():
        i = int(np.flatnonzero(naive)[0])
        raise InputError(source, "time",
                         f"line {i + 2}: {text.iloc[i]!r} has no UTC offset (write e.g. 2024-06-01T12:00+02:00)")
    times = pd.to_datetime(text, format="ISO8601", utc=True, errors="coerce")
    if times.isna().any():
        i = int(np.flatnonzero(times.isna())[0])
        raise InputError(source, "time", f"line {i + 2}: {text.iloc[i]!r} is not an ISO 8601 time")
    if offsets.nunique() == 1:
        # One offset in the file: keep the user's local clock rather than showing UTC.
        times = times.dt.tz_convert(pd.Timestamp(text.iloc[0]).tz)
    return pd.DatetimeIndex(times, name="time")


def _numeric(source, name, text):
    values = pd.to_numeric(text, errors="coerce")
    bad = values.isna() & text.notna() & (text.str.strip() != "")
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise InputError(source, name, f"line {i + 2}: {text.iloc[i]!r} is not a number")
    infinite = np.isinf(values)
    if infinite.any():
        i = int(np.flatnonzero(infinite)[0])
        raise InputError(source, name, f"line {i + 2}: {text.iloc[i]!r} is not a finite number")
    return values.to_numpy(float)
