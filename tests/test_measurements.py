"""Measurements CSV: node columns, checks, missing cells kept missing."""

import numpy as np
import pandas as pd
import pytest

from nodeforce.model.errors import InputError
from nodeforce.iotools.measurements import read_measurements

GOOD = """time,T23,T1,T17
2024-06-01T00:00:00+04:00,24.1,23.0,22.5
2024-06-01T00:15:00+04:00,,23.1,22.5
2024-06-01T00:30:00+04:00,24.3,,22.6
"""


def write(tmp_path, text):
    path = tmp_path / "measurements.csv"
    path.write_text(text)
    return path


def test_reads_node_columns_with_empty_cells_missing(tmp_path):
    m = read_measurements(write(tmp_path, GOOD))
    assert list(m.columns) == ["T23", "T1", "T17"]
    assert m.index.name == "time"
    assert m.index[2] == pd.Timestamp("2024-05-31T20:30Z")
    assert np.isnan(m["T23"].iloc[1]) and np.isnan(m["T1"].iloc[2])
    assert m["T23"].iloc[2] == 24.3
    assert int(m.notna().sum().sum()) == 7  # nothing filled in


@pytest.mark.parametrize(
    "text, column",
    [
        (GOOD.replace("time,", "date,"), "time"),  # no time column
        (GOOD.replace("2024-06-01T00:15:00+04:00", "2024-06-01 00:15"), "time"),  # naive
        (GOOD.replace("2024-06-01T00:15:00+04:00", "2024-06-01"), "time"),  # a date, no clock
        (GOOD.replace("2024-06-01T00:15:00+04:00", "01/06/2024 00:15+04:00"), "time"),  # not ISO
        (GOOD.replace("T00:30:00+04:00", "T00:15:00+04:00"), "time"),  # duplicated
        (GOOD.replace("T00:30:00+04:00", "T00:10:00+04:00"), "time"),  # goes back
        (GOOD.replace("T17", "T23"), "T23"),  # twice
        (GOOD.replace("23.1", "23,1"), "file"),  # decimal comma splits a field
        (GOOD.replace("23.1", "23.1C"), "T1"),  # non-numeric
        (GOOD.replace("22.5", "295.65").replace("22.6", "295.75"), "T17"),  # kelvin
        ("time\n2024-06-01T00:00Z\n", "T<id>"),  # nothing measured
    ],
)
def test_bad_measurements_name_the_file_and_column(tmp_path, text, column):
    path = write(tmp_path, text)
    with pytest.raises(InputError) as caught:
        read_measurements(path)
    assert caught.value.source == str(path)
    assert caught.value.field == column


def test_other_names_pass_the_reader_for_the_building_to_resolve(tmp_path):
    # a column measuring no node is refused where the building is known (tests/test_columns.py)
    m = read_measurements(write(tmp_path, GOOD.replace("T1,", "living_air,")))
    assert list(m.columns) == ["T23", "living_air", "T17"] and m["living_air"].iloc[0] == 23.0


def test_an_all_empty_column_is_still_a_measured_node(tmp_path):
    text = "time,T5,T23\n2024-06-01T00:00Z,,20\n2024-06-01T00:15Z,,21\n"
    m = read_measurements(write(tmp_path, text))
    assert list(m.columns) == ["T5", "T23"] and m["T5"].isna().all()
    assert m["T5"].isna().all()
