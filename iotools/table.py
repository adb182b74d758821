"""`nodeforce table`: columns of a Modelica table picked, renamed and written as a weather or
measurements CSV (docs/guide.md, Modelica tables).

Nothing is computed from the data: the values written are the table's, cut to the period asked
for, and a constant column (`--set`) holds exactly the value the user states.
"""

import csv
import math
from pathlib import Path
from typing import NamedTuple

import pandas as pd

from nodeforce.model.errors import InputError
from .combitimetable import read_combitimetable
from .timetable import instant, one_line, uncompressed_name, write_time_table


class Selected(NamedTuple):
    """A column to write: its name in the CSV (`out`), its name in the table (`name`), and where
    the user gave the pair, for error messages: `source` (`--select` or the file) and `at`
    ("line N: " in a file, else "")."""
    out: str
    name: str
    source: str
    at: str


def column_names(text, table_path):
    """The names of a table's columns, time first, from `--names`.

    Parameters
    ----------
    text : str
        Names separated by commas, or a CSV file (a path ending in `.csv`, or an existing file)
        with a `name` column and optionally `column_1based` (the 1-based column each name is for:
        together 1..COLS, each once) and `file` (rows naming another file than the table's are
        for that file and are not read).
    table_path : str or Path
        The table file, whose name (less a `.gz` or `.xz`) selects the rows of a `file` column.

    Returns
    -------
    list of str
    """
    path = Path(text)
    if not (text.lower().endswith(".csv") or path.is_file()):
        return [name.strip() for name in text.split(",")]
    rows = _csv_rows(path)
    if not rows or "name" not in rows[0][1]:
        raise InputError(path, "name", "no 'name' column")
    if "file" in rows[0][1]:
        table_name = uncompressed_name(table_path)
        rows = [(line, row) for line, row in rows if row["file"].strip() == table_name]
        if not rows:
            raise InputError(path, "file", f"no row for {table_name}")
    if "column_1based" not in rows[0][1]:
        return [row["name"].strip() for _, row in rows]
    by_column = {}
    for line, row in rows:
        column = row["column_1based"].strip()
        if not column.isdigit() or int(column) in by_column or not 1 <= int(column) <= len(rows):
            raise InputError(path, "column_1based", f"line {line}: {column!r}: the columns must be 1..{len(rows)}, "
                                                    "each once")
        by_column[int(column)] = row["name"].strip()
    return [by_column[c] for c in sorted(by_column)]


def selection(text):
    """The columns to write, from `--select OUT=IN,...` or `--select @FILE` (one OUT=IN a line,
    `#` comments and blank lines allowed).

    Returns
    -------
    list of Selected
    """
    if text.startswith("@"):
        source = text[1:]
        try:
            lines = Path(source).read_text(encoding="utf-8-sig").splitlines()
        except FileNotFoundError:
            raise InputError(source, "file", "not found") from None
        except (OSError, UnicodeDecodeError) as error:
            raise InputError(source, "file", one_line(error)) from None
        items = [(f"line {n}: ", line.split("#", 1)[0].strip()) for n, line in enumerate(lines, start=1)]
    else:
        source = "--select"
        items = [("", item.strip()) for item in text.split(",")]
    pairs, seen = [], set()
    for at, item in items:
        if not item and source != "--select":
            continue
        out, equals, name = (part.strip() for part in item.partition("="))
        if not (equals and out and name):
            raise InputError(source, item, f"{at}must read OUT=IN (the name to write, then the table's column "
                                           "name), e.g. T_out=Ambient_temperature")
        if out in seen or out == "time":
            raise InputError(source, out, at + ("written twice" if out in seen else "the time column is always written"))
        seen.add(out)
        pairs.append(Selected(out, name, source, at))
    if not pairs:
        raise InputError(source, "file", "selects no column")
    return pairs


def constants(text):
    """{NAME: value} from `--set NAME=VALUE,...`: columns the user states constant (e.g. a blind
    position the experiment's description fixes)."""
    values = {}
    for item in text.split(","):
        name, equals, value = (part.strip() for part in item.partition("="))
        try:
            number = float(value)
        except ValueError:
            number = math.nan
        if not (equals and name and math.isfinite(number)):
            raise InputError("--set", item.strip(), "must read NAME=VALUE with a finite number, e.g. shading_south=0")
        if name in values or name == "time":
            raise InputError("--set", name, "set twice" if name in values else "the time column is always written")
        values[name] = number
    return values


def convert_table(table_path, names, origin, select, output, table=None, start=None, end=None, constant=None):
    """Write the CSV of `nodeforce table`.

    Parameters
    ----------
    table_path : str or Path
        CombiTimeTable text file.
    names : list of str
        Its column names, time first (`column_names`).
    origin : str
        ISO 8601 time with UTC offset of 0 s.
    select : list from `selection`
    output : str or Path
        The CSV to write: `time` (ISO 8601 with offset) and the OUT columns in the order given,
        then the constant columns; values written in full.
    table : str, optional
        The table's name in the file.
    start, end : str, optional
        ISO 8601 times with UTC offset: the rows kept, both ends included.
    constant : dict, optional
        {NAME: value} of `constants`.

    Returns
    -------
    pandas.DataFrame
        What was written, indexed by time.
    """
    frame = read_combitimetable(table_path, names, origin, table=table)
    for column in select:
        if column.name not in frame.columns:
            raise InputError(column.source, column.name, f"{column.at}not a column of {table_path} "
                                                         f"(its names: {_shorten(frame.columns)})")
    constant = constant or {}
    for name in constant:
        if name in (column.out for column in select):
            raise InputError("--set", name, "also a column selected with --select")
    if frame.empty:
        raise InputError(table_path, "time", "the table has no rows")
    first = instant("--start", start) if start is not None else frame.index[0]
    last = instant("--end", end) if end is not None else frame.index[-1]
    kept = frame.loc[(frame.index >= first) & (frame.index <= last)]
    if kept.empty:
        raise InputError("--start" if start is not None else "--end", start if start is not None else end,
                         f"no row from {first.isoformat()} to {last.isoformat()} (the table runs from "
                         f"{frame.index[0].isoformat()} to {frame.index[-1].isoformat()})")
    written = pd.DataFrame({column.out: kept[column.name] for column in select}, index=kept.index)
    for name, value in constant.items():
        written[name] = value
    write_time_table(written, output)
    return written


def _csv_rows(path):
    try:
        with open(path, newline="", encoding="utf-8-sig") as handle:
            reader = csv.DictReader(handle)
            return [(n, {k.strip(): (v or "") for k, v in row.items() if k is not None})
                    for n, row in enumerate(reader, start=2)]
    except FileNotFoundError:
        raise InputError(path, "file", "not found") from None
    except (OSError, UnicodeDecodeError, csv.Error) as error:
        raise InputError(path, "file", one_line(error)) from None


def _shorten(names, at=8):
    names = list(names)
    return ", ".join(names[:at]) + (f", ... ({len(names)} in all)" if len(names) > at else "")
