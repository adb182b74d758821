"""Weather input: read and check weather files, put them on the measurement grid, convert typical years.

The bundled Miami files are reproduced, from the repository root, with

    python -m nodeforce.model.weather convert \\
        /work/venv/lib/python3.11/site-packages/pvlib/data/12839.tm2 model/data/miami_tmy2.csv \\
        --building model/data/testcell.json --building-out model/data/testcell_miami.json

(the first path is pvlib's bundled TMY2 file for Miami, wherever pvlib is installed).

Time convention for hourly sources (EPW, TMY2, TMY3). Their irradiance values are energies
received over the hour before the stamp (Wh/m2, i.e. the hour's mean W/m2) and their temperatures
are readings at the stamp. A row here is one instant used for the sun position and for the model's
inputs, so hourly rows are put at the *middle* of their hour (local standard time, the file's UTC
offset): the irradiance keeps its value (the hour mean is the best estimate at mid-hour) and the
temperature becomes the mean of the readings at the start and end of the hour (their linear
interpolation at mid-hour, as `weather_on_grid` would do). The infrared `ir_h` is an hour energy
like the other irradiances.

This module also holds the CSV checks shared with model.measurements (`read_time_table`,
`check_celsius`).
"""

import argparse
import copy
import csv
import json
import re
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pvlib

from nodeforce.model.errors import InputError

REQUIRED_COLUMNS = ("T_out", "ghi", "dni", "dhi")
OPTIONAL_COLUMNS = ("T_sky", "ir_h")
IRRADIANCE_COLUMNS = ("ghi", "dni", "dhi")
TEMPERATURE_COLUMNS = ("T_out", "T_sky")

#: A temperature column whose median exceeds this (degrees C) is taken for kelvin: no climate or
#: building has a median above 150 C, and no kelvin reading is below 150 K.
KELVIN_MEDIAN = 150.0

#: Irradiances (W/m2) below this are refused. Pyranometers read a few W/m2 below zero at night
#: (thermal offset); those pass unchanged and the model clips incident solar at 0. A value far below
#: is a sign error or a missing-value code (-999, -9999) that must not be read as data.
IRRADIANCE_FLOOR = -50.0

#: Two weather rows further apart than this many typical (median) steps bound a gap: samples
#: inside it are missing rather than interpolated across hours or days of absent data.
GAP_FACTOR = 1.5

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
        raise InputError(source, "file", f"not a readable CSV: {_one_line(error)}") from None
    raw.columns = header
    if raw.empty:
        raise InputError(source, "time", "no data rows")
    times = _parse_times(source, raw["time"])
    _check_increasing(source, times, where=lambda i: f"line {i + 2}")
    frame = pd.DataFrame(
        {name: _numeric(source, name, raw[name]) for name in header if name != "time"},
        index=times,
    )
    frame.attrs["source"] = source
    return frame


def check_celsius(frame, columns):
    """Refuse temperature columns that look like kelvin (median above `KELVIN_MEDIAN`).

    Parameters
    ----------
    frame : pandas.DataFrame
        As returned by `read_time_table` (its `attrs["source"]` names the file).
    columns : iterable of str
        Temperature columns to check, degrees C; absent or all-missing columns pass.
    """
    for name in columns:
        if name in frame and frame[name].notna().any():
            median = float(frame[name].median())
            if median > KELVIN_MEDIAN:
                raise InputError(
                    frame.attrs.get("source", "?"), name,
                    f"median {median:.1f} looks like Kelvin; temperatures must be in degrees C",
                )


def read_weather(path):
    """Read and check a weather file: the CSV of PHYSICS.md section 4, or an EPW file (by extension).

    Parameters
    ----------
    path : str or Path
        Weather CSV (columns `time`, `T_out` C, `ghi`, `dni`, `dhi` W/m2, optional `T_sky` C,
        `ir_h` W/m2 and `I_<component>` W/m2) or `.epw` file.

    Returns
    -------
    pandas.DataFrame
        Indexed by a tz-aware DatetimeIndex named "time", columns among those above, float, in
        their units; missing values are NaN. `attrs["source"]` is the path. An EPW file gives
        `T_out`, `ghi`, `dni`, `dhi`, `ir_h` at the middle of each hour (module docstring); its
        missing-value codes (99.9 C, 9999 W/m2) become NaN and the first row's `T_out`, which
        would need the reading before the file starts, is NaN.

    Raises
    ------
    InputError
        Naming the file and the column: the checks of `read_time_table`, a missing required or an
        unknown column, kelvin-looking temperatures, irradiance below `IRRADIANCE_FLOOR`, negative
        `ir_h`, an EPW typical year (years mixed; convert it with `convert_typical_year`).
    """
    source = str(path)
    if Path(source).suffix.lower() == ".epw":
        weather = _read_epw_weather(source)
    else:
        weather = read_time_table(path)
    for name in weather.columns:
        if name not in REQUIRED_COLUMNS + OPTIONAL_COLUMNS and not _is_component_irradiance(name):
            raise InputError(
                source, name,
                "unknown weather column (expected T_out, ghi, dni, dhi, T_sky, ir_h or I_<component>)",
            )
    for name in REQUIRED_COLUMNS:
        if name not in weather.columns:
            raise InputError(source, name, "required weather column is missing")
    check_celsius(weather, TEMPERATURE_COLUMNS)
    for name in weather.columns:
        if name in IRRADIANCE_COLUMNS or _is_component_irradiance(name):
            _check_at_least(weather, name, IRRADIANCE_FLOOR,
                            "more than a sensor's night offset: a sign error or a missing-value code?")
    if "ir_h" in weather:
        _check_at_least(weather, "ir_h", 0.0, "infrared irradiance cannot be negative")
    return weather


def weather_on_grid(weather, times):
    """Weather linearly interpolated in time onto the measurement grid.

    Parameters
    ----------
    weather : pandas.DataFrame
        As returned by `read_weather`.
    times : pandas.DatetimeIndex
        Target times, tz-aware (the measurement grid), within the weather's span.

    Returns
    -------
    pandas.DataFrame
        The weather's columns at `times` (index named "time"), same units. A target time equal
        to a weather time takes that row's value; between two rows the value is their linear
        interpolation, NaN if either is NaN or if the rows are more than `GAP_FACTOR` median steps
        apart (a gap in the file is missing weather, not something to invent).

    Raises
    ------
    InputError
        Naming the weather file, when `times` reach outside the weather's span.
    """
    source = weather.attrs.get("source", "weather")
    times = pd.DatetimeIndex(times, name="time")
    if len(times) and (times.min() < weather.index[0] or times.max() > weather.index[-1]):
        raise InputError(
            source, "time",
            f"weather does not cover {times.min().isoformat()} to {times.max().isoformat()} "
            f"(it runs from {weather.index[0].isoformat()} to {weather.index[-1].isoformat()})",
        )
    x = _microseconds(times)
    xp = _microseconds(weather.index)
    if len(xp) == 1:
        on_grid = pd.DataFrame(np.repeat(weather.to_numpy(float), len(x), axis=0),
                               index=times, columns=weather.columns)
        on_grid.attrs["source"] = source
        return on_grid
    left = np.clip(np.searchsorted(xp, x, side="right") - 1, 0, len(xp) - 2)
    step = xp[left + 1] - xp[left]
    w = (x - xp[left]) / step
    gap = step > GAP_FACTOR * np.median(np.diff(xp))
    values = weather.to_numpy(float)
    lo, hi = values[left], values[left + 1]
    w = w[:, None]
    # Exact hits take the row itself, so a missing neighbour cannot hide a present sample.
    blended = np.where(w == 0.0, lo, np.where(w == 1.0, hi, (1.0 - w) * lo + w * hi))
    inside_gap = gap[:, None] & (w > 0.0) & (w < 1.0)
    blended = np.where(inside_gap, np.nan, blended)
    on_grid = pd.DataFrame(blended, index=times, columns=weather.columns)
    on_grid.attrs["source"] = source
    return on_grid


def convert_typical_year(src_path, dst_csv_path, year=2001):
    """Convert a typical-year file (TMY2 `.tm2`, TMY3 `.csv`, EPW `.epw`) to a weather CSV.

    Typical years splice months from different years; the months are put in one `year`, so the
    time column is strictly increasing over 8760 hours. Rows are at mid-hour local standard time
    (module docstring); the first row's `T_out` uses the last reading of the file, the year
    being cyclic. `ir_h` is written when the source has it (EPW); TMY2 and TMY3 have no
    infrared, so the model falls back on Swinbank's sky temperature.

    Parameters
    ----------
    src_path : str or Path
        Source file; its format is chosen by extension.
    dst_csv_path : str or Path
        Weather CSV to write (columns time, T_out C, ghi, dni, dhi W/m2 [, ir_h W/m2]).
    year : int
        Calendar year given to the data; must not be a leap year (a typical year has 365 days).

    Returns
    -------
    dict
        The site: `name`, `latitude`, `longitude` (degrees), `altitude` (m), `utc_offset`
        (hours) and `timezone` (`Etc/GMT+5` style for whole-hour offsets, which is the fixed
        local standard time of the file, else `+hh:mm`).
    """
    source = str(src_path)
    if year % 4 == 0 and (year % 100 != 0 or year % 400 == 0):
        raise InputError("--year", "year", f"{year} is a leap year; a typical year has 365 days")
    suffix = Path(source).suffix.lower()
    readers = {".tm2": _read_tmy2, ".csv": _read_tmy3, ".epw": _read_epw_typical}
    if suffix not in readers:
        raise InputError(source, "file", "not a typical-year file (expected .tm2, .csv (TMY3) or .epw)")
    try:
        end_of_hour, columns, meta = readers[suffix](source, year)
    except (OSError, ValueError, KeyError, IndexError, pd.errors.ParserError) as error:
        raise InputError(source, "file", f"not a readable {suffix} typical year: {_one_line(error)}") from None
    weather = _to_mid_hour(end_of_hour, columns, cyclic=True)
    _check_increasing(source, weather.index, where=lambda i: f"record {i + 1}")
    write_weather(weather, dst_csv_path)
    return _site(meta)


def write_weather(weather, path):
    """Write a weather frame as the weather CSV: ISO 8601 times with offset, empty cells for NaN.

    Parameters
    ----------
    weather : pandas.DataFrame
        Indexed by tz-aware time, columns in the units of `read_weather`.
    path : str or Path
        CSV file to write.
    """
    out = weather.copy()
    out.index = pd.Index([t.isoformat() for t in weather.index], name="time")
    out.to_csv(path, float_format="%.6g", lineterminator="\n")


def relocate(building, metadata):
    """A copy of a building description moved to another site.

    Parameters
    ----------
    building : dict
        Building description (`nodal-building/1`); not modified.
    metadata : dict
        Site as returned by `convert_typical_year`: `latitude`, `longitude` (degrees), `altitude`
        (m) and `timezone`.

    Returns
    -------
    dict
        Deep copy of `building` with those four site fields replaced; the ground albedo and all
        else kept.
    """
    moved = copy.deepcopy(building)
    site = moved.setdefault("site", {})
    for key in ("latitude", "longitude", "altitude", "timezone"):
        site[key] = metadata[key]
    return moved


def main(argv=None):
    """`python -m nodeforce.model.weather convert SRC DST [--year Y] [--building B --building-out B2]`."""
    parser = argparse.ArgumentParser(prog="python -m nodeforce.model.weather")
    commands = parser.add_subparsers(dest="command", required=True)
    convert = commands.add_parser("convert", help="typical year (TMY2/TMY3/EPW) to weather CSV")
    convert.add_argument("src")
    convert.add_argument("dst")
    convert.add_argument("--year", type=int, default=2001)
    convert.add_argument("--building", help="building JSON to relocate to the file's site")
    convert.add_argument("--building-out", help="where to write the relocated building")
    args = parser.parse_args(argv)
    if bool(args.building) != bool(args.building_out):
        parser.error("--building and --building-out go together")
    try:
        meta = convert_typical_year(args.src, args.dst, year=args.year)
        if args.building:
            try:
                building = json.loads(Path(args.building).read_text())
            except (OSError, json.JSONDecodeError) as error:
                raise InputError(args.building, "file", _one_line(error)) from None
            moved = relocate(building, meta)
            moved["name"] = f"{building.get('name', 'Building')}, relocated to {meta['name']}"
            Path(args.building_out).write_text(json.dumps(moved, indent=2) + "\n")
    except InputError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    print(json.dumps(meta))
    return 0


def _header(source):
    try:
        with open(source, newline="", encoding="utf-8-sig") as handle:
            header = next(csv.reader(handle), None)
    except (OSError, UnicodeDecodeError) as error:
        raise InputError(source, "file", _one_line(error)) from None
    if not header:
        raise InputError(source, "file", "empty file (no header line)")
    header = [name.strip() for name in header]
    seen = set()
    for name in header:
        if not name:
            raise InputError(source, "header", "a column has no name")
        if name in seen:
            raise InputError(source, name, "column appears twice in the header")
        seen.add(name)
    return header


def _parse_times(source, text):
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


def _check_increasing(source, times, where):
    steps = np.diff(_microseconds(times))
    if (steps <= 0).any():
        i = int(np.flatnonzero(steps <= 0)[0]) + 1
        what = "repeats the previous time" if steps[i - 1] == 0 else "is before the previous time"
        raise InputError(source, "time", f"{where(i)}: {times[i].isoformat()} {what}; times must increase")


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


def _check_at_least(frame, name, floor, why):
    low = frame[name] < floor
    if low.any():
        t = frame.index[np.flatnonzero(low)[0]]
        raise InputError(
            frame.attrs.get("source", "?"), name,
            f"{frame[name][t]:g} at {t.isoformat()} is below {floor:g} W/m2 ({why})",
        )


def _is_component_irradiance(name):
    return name.startswith("I_") and len(name) > 2


def _microseconds(times):
    # Integers keep "this grid time is exactly a weather time" exact.
    return pd.DatetimeIndex(times).tz_convert("UTC").as_unit("us").asi8


def _one_line(error):
    return " ".join(str(error).split())


def _read_epw(source, coerce_year=None):
    # pvlib stamps EPW hour h (energy over h-1..h, readings at h) at h-1, the start of the hour.
    try:
        data, meta = pvlib.iotools.read_epw(source, coerce_year=coerce_year)
    except (OSError, ValueError, KeyError, IndexError, pd.errors.ParserError) as error:
        raise InputError(source, "file", f"not a readable EPW file: {_one_line(error)}") from None
    columns = {
        "T_out": data["temp_air"].where(data["temp_air"] < 99.9),
        "ghi": data["ghi"].where(data["ghi"] < 9999),
        "dni": data["dni"].where(data["dni"] < 9999),
        "dhi": data["dhi"].where(data["dhi"] < 9999),
        "ir_h": data["ghi_infrared"].where(data["ghi_infrared"] < 9999),
    }
    end_of_hour = data.index + pd.Timedelta(hours=1)
    return end_of_hour, {k: v.to_numpy(float) for k, v in columns.items()}, meta


def _read_epw_weather(source):
    end_of_hour, columns, _ = _read_epw(source)
    steps = np.diff(_microseconds(end_of_hour))
    if (steps <= 0).any():
        raise InputError(
            source, "time",
            "the EPW mixes years (a typical year): convert it to one year with "
            f"'python -m nodeforce.model.weather convert {source} OUT.csv --year YYYY'",
        )
    weather = _to_mid_hour(end_of_hour, columns, cyclic=False)
    weather.attrs["source"] = source
    return weather


def _read_epw_typical(source, year):
    end_of_hour, columns, meta = _read_epw(source, coerce_year=year)
    meta = {**meta, "name": f"{meta['city'].strip()}, {meta['country'].strip()} (EPW {meta['WMO_code'].strip()})"}
    return end_of_hour, columns, meta


def _read_tmy2(source, year):
    # pvlib gives every TMY2 row the first row's year; the calendar is rebuilt in `year` from the
    # month, day and hour (1-24, end of hour) fields. Temperatures are in tenths of a degree.
    data, meta = pvlib.iotools.read_tmy2(source)
    start_of_day = pd.to_datetime(
        pd.DataFrame({"year": year, "month": data["month"].astype(int), "day": data["day"].astype(int)})
    )
    end_of_hour = pd.DatetimeIndex(start_of_day + pd.to_timedelta(data["hour"].to_numpy(), unit="h"))
    end_of_hour = end_of_hour.tz_localize(_fixed_offset(meta["TZ"]))
    columns = {
        "T_out": data["DryBulb"].to_numpy(float) / 10.0,
        "ghi": data["GHI"].to_numpy(float),
        "dni": data["DNI"].to_numpy(float),
        "dhi": data["DHI"].to_numpy(float),
    }
    meta = {**meta, "name": f"{meta['City'].strip().title()}, {meta['State'].strip()} (TMY2 {meta['WBAN']})"}
    return end_of_hour, columns, meta


def _read_tmy3(source, year):
    # pvlib stamps TMY3 rows at the end of their hour; coerce_year puts the last (24:00) row in
    # January of the next year, which is where it belongs.
    data, meta = pvlib.iotools.read_tmy3(source, coerce_year=year, map_variables=True)
    columns = {name: data[col].to_numpy(float) for name, col in
               (("T_out", "temp_air"), ("ghi", "ghi"), ("dni", "dni"), ("dhi", "dhi"))}
    station = meta["Name"].strip().strip('"').title()
    meta = {**meta, "name": f"{station}, {meta['State']} (TMY3 {meta['USAF']})"}
    return data.index, columns, meta


def _to_mid_hour(end_of_hour, columns, cyclic):
    # Hour energies stay as they are; readings at the hour ends are averaged to the mid-hour.
    columns = dict(columns)
    reading = columns["T_out"]
    before = np.concatenate(([reading[-1] if cyclic else np.nan], reading[:-1]))
    columns["T_out"] = (before + reading) / 2.0
    index = pd.DatetimeIndex(end_of_hour - pd.Timedelta(minutes=30), name="time")
    return pd.DataFrame(columns, index=index)


def _fixed_offset(hours):
    return f"{'+' if hours >= 0 else '-'}{int(abs(hours)):02d}:{int(round(abs(hours) % 1 * 60)):02d}"


def _site(meta):
    offset = float(meta["TZ"])
    if offset == int(offset):
        # IANA's Etc zones count the other way round: Etc/GMT+5 is UTC-5.
        timezone = "UTC" if offset == 0 else f"Etc/GMT{-int(offset):+d}"
    else:
        timezone = _fixed_offset(offset)
    return {
        "name": meta["name"],
        "latitude": float(meta["latitude"]),
        "longitude": float(meta["longitude"]),
        "altitude": float(meta["altitude"]),
        "utc_offset": offset,
        "timezone": timezone,
    }


if __name__ == "__main__":
    sys.exit(main())
