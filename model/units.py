"""The model's temperatures are in degrees C: columns that look like kelvin are refused where they
enter it (a weather file, a measurement file, a measured case)."""
from .errors import InputError

#: A temperature column whose median exceeds this (degrees C) is taken for kelvin: no climate or
#: building has a median above 150 C, and no kelvin reading is below 150 K.
KELVIN_MEDIAN = 150.0


def check_celsius(frame, columns):
    """Refuse temperature columns that look like kelvin (median above `KELVIN_MEDIAN`).

    Parameters
    ----------
    frame : pandas.DataFrame
        A time table (its `attrs["source"]` names the file).
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
