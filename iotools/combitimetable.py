"""Modelica `CombiTimeTable` text files: matrices of numbers whose first column is time in seconds.

The format (Modelica.Blocks.Sources.CombiTimeTable, "text file" documentation): the file begins
with the format line `#1`; each matrix is declared `double NAME(ROWS,COLS)` (or `float`) and its
ROWS x COLS numbers follow in row-wise order, so a row may span several lines; numbers are in C
syntax (2.3, -2, +2.e4), separated by spaces, tabs, commas or semicolons; `#` starts a comment
anywhere on a line; several matrices may follow one another. Comment or blank lines before `#1`
are accepted here too.

A table's rows are read as lines when its first row ends at a line end (one row per line, or
each row wrapped over the same lines): a row that does not end at a line end is then an error
naming its line, rather than values silently shifted into the next row. A table whose first
row ends inside a line is read as one stream of numbers, as the format allows.
"""

import re

import numpy as np
import pandas as pd

from nodeforce.model.errors import InputError
from .timetable import check_column_names, instant, read_text

_VERSION = re.compile(r"#1(?![0-9.])")
_DECLARATION = re.compile(r"(?:double|float)\s+([A-Za-z_][A-Za-z0-9_]*)\s*\(\s*(\d+)\s*,\s*(\d+)\s*\)")
_SEPARATORS = re.compile(r"[ \t,;]+")
_NUMBER = r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?"


def read_combitimetable(path, names, origin, table=None):
    """Read one matrix of a CombiTimeTable text file as a time series.

    Parameters
    ----------
    path : str or Path
        The text file, or its gzip (`.gz`) or xz (`.xz`) compression, read as it is.
    names : sequence of str
        One name per column of the matrix, column 1 (time, s) included: `names[0]` names the time
        column and `names[1:]` the data columns, as a column list such as the Twin House
        `columns.csv` gives them.
    origin : str or pandas.Timestamp
        The instant of 0 s, ISO 8601 with its UTC offset (e.g. `2013-01-01T00:00+01:00`).
    table : str, optional
        The matrix's name; needed only when the file holds more than one.

    Returns
    -------
    pandas.DataFrame
        Columns `names[1:]`, float, in the file's units; indexed by a tz-aware DatetimeIndex named
        "time", `origin` + column 1 seconds, in `origin`'s UTC offset. `attrs["source"]` is the path.

    Raises
    ------
    InputError
        One line naming the file (or `--origin`), the column or field, and the line: file not
        found or not text, no `#1` line, no table or an unknown table name, a row with the wrong
        number of values, a value that is not a number, fewer or more names than columns, a name
        given twice, time not increasing, an origin without UTC offset.
    """
    source = str(path)
    start = instant("--origin", origin)
    tables = _tables(source)
    name = _choose(source, tables, table)
    declared_at, n_rows, n_cols, lines = tables[name]
    names = [str(n).strip() for n in names]
    _check_names(source, name, names, n_cols)
    split = [(number, [p for p in _SEPARATORS.split(content) if p]) for number, content in lines]
    tokens = [token for _, parts in split for token in parts]
    token_lines = np.array([number for number, parts in split for _ in parts], dtype=int)
    row_lines = _row_lines(source, name, declared_at, n_rows, n_cols,
                           [(number, len(parts)) for number, parts in split], token_lines)
    values = _numbers(source, names, n_cols, tokens, token_lines, row_lines)
    seconds = values[:, 0]
    steps = np.diff(seconds)
    if (steps <= 0).any():
        r = int(np.flatnonzero(steps <= 0)[0]) + 1
        raise InputError(source, names[0], f"line {row_lines[r]} (row {r + 1}): {seconds[r]:g} s is not after the "
                                           f"previous row's {seconds[r - 1]:g} s; time must increase (a repeated "
                                           "time, a Modelica discontinuity, has no place in a time series)")
    index = pd.DatetimeIndex(start + pd.to_timedelta(seconds, unit="s"), name="time")
    frame = pd.DataFrame(values[:, 1:], index=index, columns=names[1:])
    frame.attrs["source"] = source
    return frame


def _tables(source):
    """{name: (declaration line, rows, cols, [(line number, text without comment)])}."""
    text = read_text(source).splitlines()
    tables, current, version = {}, None, False
    for number, line in enumerate(text, start=1):
        if not version:
            if _VERSION.match(line.strip()):
                version = True
            elif line.strip() and not line.lstrip().startswith("#"):
                break
            continue
        content = line.split("#", 1)[0].strip()
        if not content:
            continue
        declaration = _DECLARATION.fullmatch(content)
        if declaration:
            name, rows, cols = declaration.group(1), int(declaration.group(2)), int(declaration.group(3))
            if name in tables:
                raise InputError(source, name, f"line {number}: a second table of this name")
            if cols < 1:
                raise InputError(source, name, f"line {number}: a table needs at least the time column")
            current = tables[name] = (number, rows, cols, [])
        elif current is None:
            raise InputError(source, "file", f"line {number}: {content[:40]!r} before any table declaration "
                                             "'double NAME(ROWS,COLS)'")
        else:
            current[3].append((number, content))
    if not version:
        raise InputError(source, "#1", "not a Modelica table text file: its first line must be the format line '#1'")
    if not tables:
        raise InputError(source, "file", "no table (a table starts with a line 'double NAME(ROWS,COLS)')")
    return tables


def _choose(source, tables, table):
    if table is None:
        if len(tables) > 1:
            raise InputError(source, "table", f"holds tables {', '.join(tables)}: say which (--table NAME)")
        return next(iter(tables))
    if table not in tables:
        raise InputError(source, table, f"no table of this name (the file holds {', '.join(tables)})")
    return table


def _check_names(source, table, names, n_cols):
    if len(names) != n_cols:
        raise InputError(source, "names", f"{len(names)} names for the {n_cols} columns of table {table} "
                                          "(the first names the time column)")
    check_column_names(source, names, "names")
    if "time" in names[1:]:
        raise InputError(source, "time", "names a data column; 'time' is the time column of the CSV written")


def _row_lines(source, table, declared_at, n_rows, n_cols, counts, token_lines):
    """The line each row starts on, from each line's (number, count of values) and each value's
    line; InputError where the values do not make n_rows x n_cols."""
    first, aligned = 0, False
    for _, count in counts:
        first += count
        if first >= n_cols:
            aligned = first == n_cols
            break
    if not aligned:
        if len(token_lines) != n_rows * n_cols:
            raise InputError(source, table, f"line {declared_at}: declared {n_rows} x {n_cols} = {n_rows * n_cols} "
                                            f"values but {len(token_lines)} follow")
        return token_lines[::n_cols]
    one_per_line = counts[0][1] == n_cols
    starts, filled, start = [], 0, None
    for number, count in counts:
        if one_per_line and count != n_cols:
            raise InputError(source, table, f"line {number} (row {len(starts) + 1}): {count} values where the "
                                            f"table has {n_cols} columns")
        start = number if filled == 0 else start
        filled += count
        if filled > n_cols:
            raise InputError(source, table, f"line {start} (row {len(starts) + 1}): the row runs to {filled} values "
                                            f"by line {number}, where the table has {n_cols} columns")
        if filled == n_cols:
            starts.append(start)
            filled = 0
    if filled:
        raise InputError(source, table, f"line {start} (row {len(starts) + 1}): {filled} values where the table "
                                        f"has {n_cols} columns")
    if len(starts) != n_rows:
        raise InputError(source, table, f"line {declared_at}: declared {n_rows} rows but {len(starts)} follow")
    return np.array(starts, dtype=int)


def _numbers(source, names, n_cols, tokens, token_lines, row_lines):
    text = pd.Series(tokens, dtype=str)
    bad = ~text.str.fullmatch(_NUMBER)
    if not bad.any():
        values = text.astype(float).to_numpy()
        bad = pd.Series(~np.isfinite(values))
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        row, col = divmod(i, n_cols)
        raise InputError(source, names[col], f"line {token_lines[i]} (row {row + 1}): {tokens[i]!r} is not a "
                                             "finite number")
    return values.reshape(-1, n_cols)
