"""Weather as the model uses it: the columns it knows, and weather onto the simulation grid.

Reading weather files is `nodeforce.iotools.weather`; this module holds no file I/O.
"""

import numpy as np
import pandas as pd

from nodeforce.model.errors import InputError

#: Every weather file has the outdoor air temperature.
REQUIRED_COLUMNS = ("T_out",)
#: Needed only where some exterior face's irradiance is computed rather than measured.
IRRADIANCE_COLUMNS = ("ghi", "dni", "dhi")
OPTIONAL_COLUMNS = ("T_sky", "ir_h", "wind_speed", "wind_direction")
TEMPERATURE_COLUMNS = ("T_out", "T_sky")

#: Two weather rows further apart than this many typical (median) steps bound a gap: samples
#: inside it are missing rather than interpolated across hours or days of absent data.
GAP_FACTOR = 1.5


def weather_on_grid(weather, times):
    """Weather linearly interpolated in time onto the measurement grid.

    Parameters
    ----------
    weather : pandas.DataFrame
        As returned by `nodeforce.iotools.weather.read_weather`.
    times : pandas.DatetimeIndex
        Target times, tz-aware (the measurement grid), within the weather's span.

    Returns
    -------
    pandas.DataFrame
        The weather's columns at `times` (index named "time"), same units. A target time equal
        to a weather time takes that row's value; between two rows the value is their linear
        interpolation, NaN if either is NaN or if the rows are more than `GAP_FACTOR` median steps
        apart (a gap in the file is missing weather, not something to invent); a
        `wind_direction` turns the short way round north. Its `attrs` are the weather's (its
        source, and an EPW's site).

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
    x = utc_microseconds(times)
    xp = utc_microseconds(weather.index)
    if len(xp) == 1:
        on_grid = pd.DataFrame(np.repeat(weather.to_numpy(float), len(x), axis=0),
                               index=times, columns=weather.columns)
        on_grid.attrs.update(weather.attrs, source=source)
        return on_grid
    left = np.clip(np.searchsorted(xp, x, side="right") - 1, 0, len(xp) - 2)
    step = xp[left + 1] - xp[left]
    w = (x - xp[left]) / step
    gap = step > GAP_FACTOR * np.median(np.diff(xp))
    values = weather.to_numpy(float)
    lo, hi = values[left], values[left + 1]
    w = w[:, None]
    if "wind_direction" in weather.columns:  # the short way round north
        k = weather.columns.get_loc("wind_direction")
        hi = hi.copy()
        hi[:, k] = lo[:, k] + turn(lo[:, k], hi[:, k])
    # Exact hits take the row itself, so a missing neighbour cannot hide a present sample.
    blended = np.where(w == 0.0, lo, np.where(w == 1.0, hi, (1.0 - w) * lo + w * hi))
    if "wind_direction" in weather.columns:
        blended[:, k] %= 360.0
    inside_gap = gap[:, None] & (w > 0.0) & (w < 1.0)
    blended = np.where(inside_gap, np.nan, blended)
    on_grid = pd.DataFrame(blended, index=times, columns=weather.columns)
    on_grid.attrs.update(weather.attrs, source=source)
    return on_grid


def check_columns(building, weather):
    """Refuse a weather column the building has no use for: a misspelt name is caught, not ignored.

    Parameters
    ----------
    building : Building
    weather : pandas.DataFrame
        As returned by `nodeforce.iotools.weather.read_weather` (`attrs["source"]` names the file).

    Raises
    ------
    InputError
        Naming the weather file and the first column that is neither standard (`T_out`, `ghi`,
        `dni`, `dhi`, `T_sky`, `ir_h`, `I_<exterior component>`) nor one the building refers to
        (`building.input_columns`).
    """
    exterior = [c.name for c in building.exterior_components]
    known = set(REQUIRED_COLUMNS + IRRADIANCE_COLUMNS + OPTIONAL_COLUMNS + building.input_columns)
    known.update(f"I_{name}" for name in exterior)
    for name in weather.columns:
        if name in known:
            continue
        if name.startswith("I_"):
            problem = (f"names no exterior component of {building.source} (its exterior components: "
                       f"{', '.join(exterior) or 'none'}): a misspelt name?")
        else:
            referred = ", ".join(building.input_columns) or "none"
            problem = (f"neither a standard weather column ({', '.join(REQUIRED_COLUMNS + IRRADIANCE_COLUMNS + OPTIONAL_COLUMNS)}, "
                       f"I_<exterior component>) nor one {building.source} refers to ({referred}): a misspelt name?")
        raise InputError(weather.attrs.get("source", "weather"), name, problem)


def turn(a, b):
    """The turn (deg) from direction `a` to direction `b` the short way round north, as EnergyPlus
    interpolates the wind's direction: b - a within half a turn, else a turn the other way; half
    a turn exactly as it reads."""
    d = np.asarray(b, float) - np.asarray(a, float)
    return np.where(d > 180.0, d - 360.0, np.where(d < -180.0, d + 360.0, d))


def utc_microseconds(times):
    """Integer microseconds since the epoch (UTC) of tz-aware times."""
    # Integers keep "this grid time is exactly a weather time" exact.
    return pd.DatetimeIndex(times).tz_convert("UTC").as_unit("us").asi8
