"""Modelica CombiTimeTable text files and `nodeforce table`: time origin, names, one-line errors."""

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from nodeforce.cli import main
from nodeforce.iotools.combitimetable import read_combitimetable
from nodeforce.iotools.measurements import read_measurements
from nodeforce.iotools.table import column_names
from nodeforce.iotools.weather import read_weather
from nodeforce.model.errors import InputError

TWIN_HOUSE = Path(__file__).resolve().parents[1] / "examples" / "twinhouse_n2" / "data" / "exp1"
NAMES = ["time", "T_a", "T_b"]
ORIGIN = "2024-06-01T00:00-05:00"
# Three rows of three columns, every separator the format allows, comments anywhere.
SMALL = """#1
# written by hand
double tab(3,3)   # time, T_a, T_b
0 20.5 -1e1
600,21;-2.5e+0
1200\t+22. .5
"""


def write(tmp_path, text, name="table.txt"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_a_small_table_takes_its_origin_and_names(tmp_path):
    frame = read_combitimetable(write(tmp_path, SMALL), NAMES, ORIGIN)
    assert list(frame.columns) == ["T_a", "T_b"]
    assert frame.index.name == "time"
    assert list(frame.index) == [pd.Timestamp("2024-06-01T00:00-05:00"), pd.Timestamp("2024-06-01T00:10-05:00"),
                                 pd.Timestamp("2024-06-01T05:20Z")]
    assert frame.index[0].utcoffset() == pd.Timedelta(hours=-5)  # the origin's clock is kept
    assert frame["T_a"].tolist() == [20.5, 21.0, 22.0]
    assert frame["T_b"].tolist() == [-10.0, -2.5, 0.5]


@pytest.mark.parametrize("body", [
    "0 20.5 -1e1 600 21 -2.5 1200 22 0.5\n",  # one stream of numbers
    "0 20.5\n-1e1\n600 21\n-2.5\n1200 22\n0.5\n",  # each row wrapped over two lines
    "0\n20.5 -1e1 600\n21 -2.5\n1200 22 0.5\n",  # rows starting inside lines
])
def test_rows_may_span_lines_as_the_format_allows(tmp_path, body):
    frame = read_combitimetable(write(tmp_path, "#1\ndouble tab(3,3)\n" + body), NAMES, ORIGIN)
    expected = read_combitimetable(write(tmp_path, SMALL, "small.txt"), NAMES, ORIGIN)
    pd.testing.assert_frame_equal(frame, expected)


@pytest.mark.parametrize("suffix, compress", [(".gz", "gzip"), (".xz", "lzma")])
def test_a_compressed_table_reads_as_its_text_and_a_broken_one_is_one_line(tmp_path, suffix, compress):
    import importlib
    module = importlib.import_module(compress)
    packed = tmp_path / f"table.txt{suffix}"
    packed.write_bytes(module.compress(SMALL.encode()))
    expected = read_combitimetable(write(tmp_path, SMALL), NAMES, ORIGIN)
    pd.testing.assert_frame_equal(read_combitimetable(packed, NAMES, ORIGIN), expected)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["table.txt", packed.name]  # nothing unpacked beside it
    # a names file's `file` column names the table uncompressed
    names = tmp_path / "columns.csv"
    names.write_text("file,column_1based,name\ntable.txt,1,time\ntable.txt,2,T_a\ntable.txt,3,T_b\n")
    assert column_names(str(names), packed) == NAMES
    broken = tmp_path / f"broken.txt{suffix}"
    broken.write_bytes(SMALL.encode())  # plain text under a compressed name
    with pytest.raises(InputError) as caught:
        read_combitimetable(broken, NAMES, ORIGIN)
    assert caught.value.source == str(broken) and caught.value.field == "file"
    assert "\n" not in str(caught.value)


def test_a_file_of_several_tables_reads_the_one_named(tmp_path):
    text = SMALL + "double other(2,2)\n0 1\n10 2\n"
    path = write(tmp_path, text)
    other = read_combitimetable(path, ["t", "x"], ORIGIN, table="other")
    assert other["x"].tolist() == [1.0, 2.0]
    assert other.index[1] - other.index[0] == pd.Timedelta(seconds=10)
    with pytest.raises(InputError, match="tab, other") as caught:
        read_combitimetable(path, NAMES, ORIGIN)
    assert caught.value.field == "table"
    with pytest.raises(InputError, match="tab, other") as caught:
        read_combitimetable(path, NAMES, ORIGIN, table="data")
    assert caught.value.field == "data"


@pytest.mark.parametrize("text, names, field, where", [
    (SMALL.replace("#1\n", ""), NAMES, "#1", ""),  # not a table file
    ("#1\n# nothing here\n", NAMES, "file", ""),  # no table
    (SMALL.replace("600,21;-2.5e+0", "600,21"), NAMES, "tab", "line 5 (row 2)"),  # a short row
    (SMALL.replace("600,21;-2.5e+0", "600,21,-2.5,7"), NAMES, "tab", "line 5 (row 2)"),  # a long row
    (SMALL.replace(";-2.5e+0", ";-2.5C"), NAMES, "T_b", "line 5 (row 2)"),  # not a number
    (SMALL.replace("+22.", "nan"), NAMES, "T_a", "line 6 (row 3)"),  # not C syntax
    (SMALL.replace("1200\t", "600\t"), NAMES, "time", "line 6 (row 3)"),  # time repeats
    (SMALL.replace("1200\t", "100\t"), NAMES, "time", "line 6 (row 3)"),  # time goes back
    (SMALL.replace("(3,3)", "(4,3)"), NAMES, "tab", "line 3"),  # fewer rows than declared
    (SMALL, NAMES[:2], "names", ""),  # fewer names than columns
    (SMALL, NAMES + ["T_c"], "names", ""),  # more names than columns
    (SMALL, ["time", "T_a", "T_a"], "T_a", ""),  # a name twice
])
def test_bad_tables_are_one_line_naming_file_column_and_line(tmp_path, text, names, field, where):
    path = write(tmp_path, text)
    with pytest.raises(InputError) as caught:
        read_combitimetable(path, names, ORIGIN)
    assert caught.value.source == str(path)
    assert caught.value.field == field
    assert caught.value.problem.startswith(where)
    assert "\n" not in str(caught.value)


def test_missing_file_and_origin_without_offset(tmp_path):
    with pytest.raises(InputError) as caught:
        read_combitimetable(tmp_path / "nowhere.txt", NAMES, ORIGIN)
    assert (caught.value.source, caught.value.field, caught.value.problem) == (str(tmp_path / "nowhere.txt"),
                                                                               "file", "not found")
    with pytest.raises(InputError) as caught:
        read_combitimetable(write(tmp_path, SMALL), NAMES, "2024-06-01T00:00")
    assert caught.value.source == "--origin" and "UTC offset" in caught.value.problem


def test_names_file_orders_by_column_and_refuses_a_gap(tmp_path):
    names = write(tmp_path, "name,column_1based\nT_b,3\ntime,1\nT_a,2\n", "names.csv")
    assert column_names(str(names), "table.txt") == NAMES
    assert column_names("time, T_a,T_b", "table.txt") == NAMES
    several = write(tmp_path, "file,name\nother.txt,x\ntable.txt,time\ntable.txt,T_a\ntable.txt,T_b\n", "files.csv")
    assert column_names(str(several), tmp_path / "table.txt") == NAMES  # the rows of this file only
    gap = write(tmp_path, "name,column_1based\nT_b,4\ntime,1\nT_a,2\n", "gap.csv")
    with pytest.raises(InputError) as caught:
        column_names(str(gap), "table.txt")
    assert caught.value.source == str(gap) and caught.value.field == "column_1based"
    assert caught.value.problem.startswith("line 2")


def table_command(tmp_path, *extra):
    table = write(tmp_path, SMALL)
    out = tmp_path / "out.csv"
    return main(["table", str(table), "--names", ",".join(NAMES), "--origin", ORIGIN, "-o", str(out),
                 *extra]), out


def test_table_command_selects_renames_cuts_and_sets(tmp_path, capsys):
    select = write(tmp_path, "# outdoor air\nT_out=T_b\n\nT23 = T_a  # the zone\n", "select.txt")
    status, out = table_command(tmp_path, "--select", f"@{select}", "--start", "2024-06-01T05:10Z",
                                "--set", "shading_south=0,ghi=12.5")
    assert status == 0
    lines = out.read_text().splitlines()
    assert lines[0] == "time,T_out,T23,shading_south,ghi"
    assert lines[1:] == ["2024-06-01T00:10:00-05:00,-2.5,21.0,0.0,12.5",
                         "2024-06-01T00:20:00-05:00,0.5,22.0,0.0,12.5"]
    weather = read_weather(out)
    assert weather["T_out"].tolist() == [-2.5, 0.5]
    bad = write(tmp_path, "T_out=T_b\nT23 T_a\n", "bad_select.txt")
    assert table_command(tmp_path, "--select", f"@{bad}")[0] == 2
    assert capsys.readouterr().err.strip() == f"nodeforce: {bad}: T23 T_a: line 2: must read OUT=IN (the name " \
                                              "to write, then the table's column name), e.g. T_out=Ambient_temperature"
    status, out = table_command(tmp_path, "--select", "T1=T_a,T2=T_b", "--end", "2024-06-01T00:10-05:00")
    assert status == 0
    measured = read_measurements(out)
    assert measured["T1"].tolist() == [20.5, 21.0] and measured["T2"].tolist() == [-10.0, -2.5]


@pytest.mark.parametrize("extra, start", [
    (["--select", "T_out=T_c"], "nodeforce: --select: T_c: not a column of"),
    (["--select", "T_out"], "nodeforce: --select: T_out: must read OUT=IN"),
    (["--select", "T_out=T_a,T_out=T_b"], "nodeforce: --select: T_out: written twice"),
    (["--select", "T_out=T_a", "--set", "shading=open"], "nodeforce: --set: shading=open: "),
    (["--select", "T_out=T_a", "--start", "2024-06-02T00:00Z"], "nodeforce: --start: 2024-06-02T00:00Z: no row"),
    (["--select", "T_out=T_a", "--origin", "2024-06-01"], "nodeforce: --origin: 2024-06-01: needs a UTC offset"),
    (["--select", "@nowhere.txt"], "nodeforce: nowhere.txt: file: not found"),
])
def test_table_command_bad_input_is_one_line_exit_2(tmp_path, capsys, extra, start):
    status, _ = table_command(tmp_path, *extra)
    err = capsys.readouterr().err.strip()
    assert status == 2 and "\n" not in err
    assert err.startswith(start)


@pytest.fixture(scope="module")
def twin_house():
    """The repository's Twin House table, read compressed (columns.csv names it uncompressed)."""
    return TWIN_HOUSE / "validationdataN2Exp1.txt.gz", TWIN_HOUSE / "columns.csv"


def test_twin_house_first_row_is_21_august_cet_and_values_match_loadtxt(twin_house):
    table, names = twin_house
    frame = read_combitimetable(table, column_names(str(names), table), "2013-01-01T00:00+01:00")
    assert frame.index[0] == pd.Timestamp("2013-08-21T00:00:00+01:00")
    assert frame.index[0].isoformat() == "2013-08-21T00:00:00+01:00"
    assert frame.index[-1] == pd.Timestamp("2013-10-01T00:00:00+01:00")
    reference = np.loadtxt(table, comments="#", skiprows=2)  # the README's own way of reading it
    assert frame.shape == (reference.shape[0], reference.shape[1] - 1)
    assert np.array_equal(frame.to_numpy(), reference[:, 1:])
    assert list(frame.columns[:2]) == ["N2_attic_east_AT", "N2_attic_west_AT"]
    assert frame["Ambient_temperature"].to_numpy()[0] == reference[0, 35]  # 1-based column 36


def test_twin_house_weather_through_the_command(twin_house, tmp_path):
    table, names = twin_house
    out = tmp_path / "weather.csv"
    assert main(["table", str(table), "--names", str(names), "--origin", "2013-01-01T00:00+01:00",
                 "--select", "T_out=Ambient_temperature,ghi=Solar_radiation_global_horizontal,"
                             "dhi=Solar_radiation_diffuse_horizontal,ir_h=Longwave_radiation_horizontal",
                 "--start", "2013-09-20T00:00+01:00", "--end", "2013-09-21T00:00+01:00", "-o", str(out)]) == 0
    weather = read_weather(out)
    assert len(weather) == 24 * 6 + 1  # every 600 s, both ends included
    assert weather.index[0].isoformat() == "2013-09-20T00:00:00+01:00"
    reference = np.loadtxt(table, comments="#", skiprows=2)
    row = int(np.flatnonzero(reference[:, 0] == (pd.Timestamp("2013-09-20T00:00+01:00")
                                                 - pd.Timestamp("2013-01-01T00:00+01:00")).total_seconds())[0])
    assert np.array_equal(weather["ir_h"].to_numpy(), reference[row:row + 145, 42])
