"""Hourly weather sources (EPW, TMY2, TMY3) read through pvlib, rows put where each column was measured.

Time convention. These files' irradiance values are energies received over the hour before the
stamp (Wh/m2, i.e. the hour's mean W/m2) and their temperatures are readings at the stamp. A row
here is one instant used for the sun position and for the model's inputs, which
`nodeforce.model.weather.weather_on_grid` interpolates linearly between rows.

An EPW is read as EnergyPlus reads its own format (WeatherManager.cc, at each of its steps): the
readings `EPW_READINGS` (the air temperature, the wind, and the sky's infrared, which EnergyPlus
interpolates as it does the air) linear between the hours' ends, the sun's energies linear
between the hours' middles. Its rows are every half hour (`to_half_hours`): at an hour's end the
readings as read and the sun the mean of the two hours about it, at its middle the sun as read
and the readings the mean of the hour's two ends (a wind direction the mean the short way round
north), so that interpolating between rows follows each column between its own stamps exactly.
A TMY2 or TMY3 file's rows are at the *middle* of their hour (`to_mid_hour`, local standard
time, the file's UTC offset): the irradiance keeps its value (the hour mean is the best estimate
at mid-hour) and the temperature (and the wind speed) becomes the mean of the readings at the
start and end of the hour, which between two rows smooths the readings' hour-to-hour course a
little (the project's TMY records and the bundled Miami year are made so).

Each reader returns `(end_of_hour, columns, meta)`: the tz-aware end-of-hour stamps, a dict of
float arrays in the weather CSV's names and units, and pvlib's metadata with a `name` for the site.
"""

import numpy as np
import pandas as pd
import pvlib

from nodeforce.model.errors import InputError
from nodeforce.model.weather import turn
from .timetable import one_line


# the columns read at an instant, not accumulated over the hour
READINGS = ("T_out", "wind_speed")
# an EPW's columns EnergyPlus interpolates between the hours' ends
EPW_READINGS = ("T_out", "wind_speed", "wind_direction", "ir_h")


def read_epw(source, coerce_year=None):
    """EPW hours: `T_out` C, `ghi`, `dni`, `dhi`, `ir_h` W/m2, `wind_speed` m/s and `wind_direction`
    deg from north (the station's, at 10 m), missing-value codes as NaN."""
    # pvlib stamps EPW hour h (energy over h-1..h, readings at h) at h-1, the start of the hour.
    try:
        data, meta = pvlib.iotools.read_epw(source, coerce_year=coerce_year)
    except (OSError, ValueError, KeyError, IndexError, pd.errors.ParserError) as error:
        raise InputError(source, "file", f"not a readable EPW file: {one_line(error)}") from None
    columns = {
        "T_out": data["temp_air"].where(data["temp_air"] < 99.9),
        "ghi": data["ghi"].where(data["ghi"] < 9999),
        "dni": data["dni"].where(data["dni"] < 9999),
        "dhi": data["dhi"].where(data["dhi"] < 9999),
        "ir_h": data["ghi_infrared"].where(data["ghi_infrared"] < 9999),
        "wind_speed": data["wind_speed"].where(data["wind_speed"] < 999),
        "wind_direction": data["wind_direction"].where(data["wind_direction"] < 999),
    }
    end_of_hour = data.index + pd.Timedelta(hours=1)
    meta = {**meta, "name": f"{meta['city'].strip()}, {meta['country'].strip()} (EPW {meta['WMO_code'].strip()})"}
    return end_of_hour, {k: v.to_numpy(float) for k, v in columns.items()}, meta


def read_tmy2(source, year):
    """TMY2 hours put in one calendar `year`: `T_out` C, `ghi`, `dni`, `dhi` W/m2."""
    # pvlib gives every TMY2 row the first row's year; the calendar is rebuilt in `year` from the
    # month, day and hour (1-24, end of hour) fields. Temperatures are in tenths of a degree.
    data, meta = pvlib.iotools.read_tmy2(source)
    start_of_day = pd.to_datetime(
        pd.DataFrame({"year": year, "month": data["month"].astype(int), "day": data["day"].astype(int)})
    )
    end_of_hour = pd.DatetimeIndex(start_of_day + pd.to_timedelta(data["hour"].to_numpy(), unit="h"))
    end_of_hour = end_of_hour.tz_localize(fixed_offset(meta["TZ"]))
    columns = {
        "T_out": data["DryBulb"].to_numpy(float) / 10.0,
        "ghi": data["GHI"].to_numpy(float),
        "dni": data["DNI"].to_numpy(float),
        "dhi": data["DHI"].to_numpy(float),
    }
    meta = {**meta, "name": f"{meta['City'].strip().title()}, {meta['State'].strip()} (TMY2 {meta['WBAN']})"}
    return end_of_hour, columns, meta


def read_tmy3(source, year):
    """TMY3 hours put in one calendar `year`: `T_out` C, `ghi`, `dni`, `dhi` W/m2, `wind_speed` m/s
    and `wind_direction` deg from north."""
    # pvlib stamps TMY3 rows at the end of their hour; coerce_year puts the last (24:00) row in
    # January of the next year, which is where it belongs.
    data, meta = pvlib.iotools.read_tmy3(source, coerce_year=year, map_variables=True)
    columns = {name: data[col].to_numpy(float) for name, col in
               (("T_out", "temp_air"), ("ghi", "ghi"), ("dni", "dni"), ("dhi", "dhi"), ("wind_speed", "wind_speed"),
                ("wind_direction", "wind_direction"))}
    station = meta["Name"].strip().strip('"').title()
    meta = {**meta, "name": f"{station}, {meta['State']} (TMY3 {meta['USAF']})"}
    return data.index, columns, meta


def to_mid_hour(end_of_hour, columns, cyclic):
    """The weather frame of hourly columns, rows at mid-hour (module docstring).

    Hour energies stay as they are; `T_out` and `wind_speed` readings at the hour ends are
    averaged to the mid-hour, the first row's earlier reading being the last of the file when
    `cyclic` (a typical year) and missing (NaN) otherwise. A wind direction keeps its reading at
    the hour's end: the mean of two directions either side of north is not their arithmetic one.
    """
    columns = dict(columns)
    for name in READINGS:
        if name in columns:
            reading = columns[name]
            before = np.concatenate(([reading[-1] if cyclic else np.nan], reading[:-1]))
            columns[name] = (before + reading) / 2.0
    index = pd.DatetimeIndex(end_of_hour - pd.Timedelta(minutes=30), name="time")
    return pd.DataFrame(columns, index=index)


def to_half_hours(end_of_hour, columns, cyclic):
    """The weather frame of an EPW's hours, a row every half hour (module docstring): the middle of
    each hour, then its end, the last hour's end left out (the sun after the last middle is
    unknown). Before the first hour's middle, the reading before the file starts is its last
    when `cyclic` (a typical year), else missing (NaN)."""
    n = len(end_of_hour)
    rows = {}
    for name, values in columns.items():
        values = np.asarray(values, float)
        column = np.empty(2 * n - 1)
        if name in EPW_READINGS:
            before = np.concatenate(([values[-1] if cyclic else np.nan], values[:-1]))
            column[0::2] = (mean_direction(before, values) if name == "wind_direction" else (before + values) / 2.0)
            column[1::2] = values[:-1]
        else:
            column[0::2] = values
            column[1::2] = (values[:-1] + values[1:]) / 2.0
        rows[name] = column
    middles = end_of_hour - pd.Timedelta(minutes=30)
    index = pd.DatetimeIndex(np.stack([middles, end_of_hour]).T.ravel()[:-1], name="time")
    return pd.DataFrame(rows, index=index)


def mean_direction(a, b):
    """The direction halfway between directions `a` and `b` (deg from north), the short way round
    (`model.weather.turn`)."""
    return (a + turn(a, b) / 2.0) % 360.0


def epw_site(source):
    """The site of an EPW's LOCATION line (its first), where its weather was recorded: `name`
    (city and WMO station), `latitude`, `longitude` (deg, north and east positive), `utc_offset`
    (h, the file's standard time), `timezone` (`zone_name` of that offset) and `altitude` (m)."""
    try:
        with open(source, encoding="latin-1") as f:
            fields = f.readline().strip().split(",")
        latitude, longitude, offset, altitude = (float(v) for v in fields[6:10])
    except OSError as error:
        raise InputError(source, "file", one_line(error)) from None
    except ValueError:
        raise InputError(source, "LOCATION", "the first line must be LOCATION,city,state,country,source,WMO,"
                                             "latitude,longitude,time zone,elevation (numbers)") from None
    return {"name": f"{fields[1]} {fields[5]}", "latitude": latitude, "longitude": longitude,
            "utc_offset": offset, "timezone": zone_name(offset), "altitude": altitude}


def zone_name(hours):
    """The fixed time zone of a standard time `hours` from UTC: "UTC", "Etc/GMT+5" for UTC-5
    (IANA's Etc zones count the other way round), "+05:30" where it is not a whole hour."""
    if hours != int(hours):
        return fixed_offset(hours)
    return "UTC" if hours == 0 else f"Etc/GMT{-int(hours):+d}"


def fixed_offset(hours):
    """"+hh:mm" of a UTC offset in hours."""
    return f"{'+' if hours >= 0 else '-'}{int(abs(hours)):02d}:{int(round(abs(hours) % 1 * 60)):02d}"
