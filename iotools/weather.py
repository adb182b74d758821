"""Weather files: the weather CSV of docs/model.md section 4 or an EPW file, read and checked.

An EPW is read as EnergyPlus reads it: its months, days and hours in one calendar year, its rows
every half hour so that each column follows EnergyPlus's interpolation (`nodeforce.iotools.hourly`).
"""

from pathlib import Path

import numpy as np
import pandas as pd

from nodeforce.model.errors import InputError
from nodeforce.model.weather import IRRADIANCE_COLUMNS, REQUIRED_COLUMNS, TEMPERATURE_COLUMNS, utc_microseconds
from .hourly import epw_site, read_epw, to_half_hours
from nodeforce.model.units import check_celsius
from .timetable import read_time_table

#: The calendar year an EPW typical year is read in when none is given: the one on which
#: `nodeforce convert` reads an IDF's schedules (its 1 January a Sunday, EnergyPlus's default
#: start of a run period).
TYPICAL_YEAR = 2017

#: Irradiances (W/m2) below this are refused. Pyranometers read a few W/m2 below zero at night
#: (thermal offset); those pass unchanged and the model clips incident solar at 0. A value far below
#: is a sign error or a missing-value code (-999, -9999) that must not be read as data.
IRRADIANCE_FLOOR = -50.0


def read_weather(path, year=None, times=None):
    """Read and check a weather file: the CSV of docs/model.md section 4, or an EPW file (by extension).

    Parameters
    ----------
    path : str or Path
        Weather CSV or `.epw` file. The CSV has `time` and `T_out` (C); `ghi`, `dni`, `dhi` (W/m2)
        where some face's irradiance is computed; optionally `T_sky` (C), `ir_h` (W/m2),
        `I_<component>` (W/m2) and any column a building file refers to by name (heat inputs,
        boundary and supply temperatures, irradiance, shading). Which columns a building may use
        is checked where the building is known (`nodeforce.model.weather.check_columns`).
    year : int, optional
        The calendar year an EPW is read in, as EnergyPlus reads any EPW: its months, days and
        hours, whatever years its rows carry. None: the file's own year where its rows run in
        time order (a record of actual weather), else (a typical year, whose months come from
        different years) the year of the first of `times`, or `TYPICAL_YEAR` without them. In a
        leap year, 29 February has no row: a gap, as any missing weather. Only for an EPW: a
        CSV's times are its own.
    times : pandas.DatetimeIndex, optional
        The record's times (its measurements'), whose year an EPW typical year is read in when
        `year` is not given.

    Returns
    -------
    pandas.DataFrame
        Indexed by a tz-aware DatetimeIndex named "time", the file's columns, float, in their
        units; missing values are NaN. `attrs["source"]` is the path. An EPW file gives
        `T_out`, `ghi`, `dni`, `dhi`, `ir_h`, `wind_speed`, `wind_direction` every half hour
        (`iotools.hourly`: the readings as read at the hours' ends, the sun at their middles); its
        missing-value codes (99.9 C, 9999 W/m2) become NaN and the first row's `T_out`, which
        would need the reading before the file starts, is NaN; that of a year read in another
        (a typical year, or `year` given) is the mean of its first and last readings, the year
        taken as cyclic, as `nodeforce.iotools.typical_year.convert_typical_year` writes it.
        `attrs["typical_year"]` says whether the EPW's own rows mixed years; `attrs["site"]` is
        where it was recorded (`iotools.hourly.epw_site`), the site a run under it computes at
        (`nodeforce.model.site.run_building`). A CSV has no site.

    Raises
    ------
    InputError
        Naming the file and the column: the checks of `read_time_table`, no `T_out`, kelvin-looking
        `T_out` or `T_sky`, irradiance below `IRRADIANCE_FLOOR`, negative
        `ir_h`, `year` given for a CSV.
    """
    source = str(path)
    if Path(source).suffix.lower() == ".epw":
        weather = _read_epw_weather(source, year, None if times is None or not len(times) else times[0].year)
    elif year is not None:
        raise InputError(source, "year", f"{year}: a year is given to an EPW, whose rows EnergyPlus reads in "
                                         "any calendar year; a weather CSV's times are its own")
    else:
        weather = read_time_table(path)
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


def _read_epw_weather(source, year, record_year):
    end_of_hour, columns, _ = read_epw(source)
    typical = bool((np.diff(utc_microseconds(end_of_hour)) <= 0).any())
    if typical or year is not None:
        year = year if year is not None else record_year or TYPICAL_YEAR
        # each hour put in `year` by its start, so that the last (ending at 24:00 on 31 December)
        # stays the year's, as pvlib's coerce_year does, without reading the file again
        start = end_of_hour - pd.Timedelta(hours=1)
        try:
            start = pd.DatetimeIndex([t.replace(year=year) for t in start])
        except ValueError:
            raise InputError(source, "year", f"{year} has no 29 February, which the EPW has") from None
        end_of_hour = start + pd.Timedelta(hours=1)
        # a year put in one calendar, as EnergyPlus runs it, is cyclic: its first hour follows its last
        weather = to_half_hours(end_of_hour, columns, cyclic=True)
    else:
        weather = to_half_hours(end_of_hour, columns, cyclic=False)
    weather.attrs.update(source=source, typical_year=typical, site=epw_site(source))
    return weather


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
