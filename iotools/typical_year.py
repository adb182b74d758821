"""Typical years (TMY2, TMY3, EPW) converted to the weather CSV, and a building moved to their site.

The bundled Miami files are reproduced, from the repository root, with

    python -m nodeforce.iotools.typical_year convert \\
        "$(python -c 'import pvlib, pathlib; print(pathlib.Path(pvlib.__file__).parent)')/data/12839.tm2" \\
        model/data/miami_tmy2.csv \\
        --building model/data/testcell.json --building-out model/data/testcell_miami.json

(the first path is pvlib's bundled TMY2 file for Miami, wherever pvlib is installed).
"""

import argparse
import copy
import json
import sys
from pathlib import Path

import pandas as pd

from nodeforce.model.errors import InputError
from .hourly import read_epw, read_tmy2, read_tmy3, to_half_hours, to_mid_hour, zone_name
from .timetable import check_increasing, one_line, write_time_table


def convert_typical_year(src_path, dst_csv_path, year=2001):
    """Convert a typical-year file (TMY2 `.tm2`, TMY3 `.csv`, EPW `.epw`) to a weather CSV.

    Typical years splice months from different years; the months are put in one `year`, so the
    time column is strictly increasing over the year. An EPW's rows are every half hour, as
    `read_weather` reads it, a TMY2's or TMY3's at mid-hour, local standard time (`iotools.hourly`);
    the first row's `T_out` uses the last reading of the file, the year being cyclic. `ir_h` is written when the source has it (EPW); TMY2 and TMY3 have no
    infrared, so the model falls back on Swinbank's sky temperature.

    Parameters
    ----------
    src_path : str or Path
        Source file; its format is chosen by extension.
    dst_csv_path : str or Path
        Weather CSV to write (columns time, T_out C, ghi, dni, dhi W/m2 [, ir_h W/m2] [, wind_speed
        m/s, wind_direction deg: EPW and TMY3]), numbers
        to 6 significant digits.
    year : int
        Calendar year given to the data; must not be a leap year (a typical year has 365 days).

    Returns
    -------
    dict
        The site: `name`, `latitude`, `longitude` (degrees), `altitude` (m), `utc_offset`
        (hours), `timezone` (`Etc/GMT+5` style for whole-hour offsets, which is the fixed
        local standard time of the file, else `+hh:mm`) and `ground_temperature` (C), the
        year's mean air temperature: the ground a few metres down, where the seasons no longer
        reach, stays near it (the deep-ground estimate a diagnosis holds a ground coupling's
        temperature at where the data leave it free, docs/model.md section 7, Priors).
    """
    source = str(src_path)
    if year % 4 == 0 and (year % 100 != 0 or year % 400 == 0):
        raise InputError("--year", "year", f"{year} is a leap year; a typical year has 365 days")
    suffix = Path(source).suffix.lower()
    readers = {".tm2": read_tmy2, ".csv": read_tmy3, ".epw": lambda s, y: read_epw(s, coerce_year=y)}
    if suffix not in readers:
        raise InputError(source, "file", "not a typical-year file (expected .tm2, .csv (TMY3) or .epw)")
    try:
        end_of_hour, columns, meta = readers[suffix](source, year)
    except (OSError, ValueError, KeyError, IndexError, pd.errors.ParserError) as error:
        raise InputError(source, "file", f"not a readable {suffix} typical year: {one_line(error)}") from None
    weather = (to_half_hours if suffix == ".epw" else to_mid_hour)(end_of_hour, columns, cyclic=True)
    check_increasing(source, weather.index, where=lambda i: f"record {i + 1}")
    write_time_table(weather, dst_csv_path, float_format="%.6g")
    return {**_site(meta), "ground_temperature": round(float(weather["T_out"].mean()), 2)}


def relocate(building, metadata):
    """A copy of a building description moved to another site.

    Parameters
    ----------
    building : dict
        Building description (`nodal-building/1`); not modified.
    metadata : dict
        Site as returned by `convert_typical_year`: `latitude`, `longitude` (degrees), `altitude`
        (m), `timezone` and, where given, `ground_temperature` (C).

    Returns
    -------
    dict
        Deep copy of `building` with those site fields replaced; the ground albedo and all else
        kept.
    """
    moved = copy.deepcopy(building)
    site = moved.setdefault("site", {})
    for key in ("latitude", "longitude", "altitude", "timezone", "ground_temperature"):
        if key in metadata:
            site[key] = metadata[key]
    return moved


def main(argv=None):
    """`python -m nodeforce.iotools.typical_year convert SRC DST [--year Y] [--building B --building-out B2]`."""
    parser = argparse.ArgumentParser(prog="python -m nodeforce.iotools.typical_year")
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
                raise InputError(args.building, "file", one_line(error)) from None
            moved = relocate(building, meta)
            moved["name"] = f"{building.get('name', 'Building')}, relocated to {meta['name']}"
            Path(args.building_out).write_text(json.dumps(moved, indent=2) + "\n")
    except InputError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    print(json.dumps(meta))
    return 0


def _site(meta):
    offset = float(meta["TZ"])
    return {
        "name": meta["name"],
        "latitude": float(meta["latitude"]),
        "longitude": float(meta["longitude"]),
        "altitude": float(meta["altitude"]),
        "utc_offset": offset,
        "timezone": zone_name(offset),
    }


if __name__ == "__main__":
    sys.exit(main())
