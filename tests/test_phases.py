"""The phases file and each model's error phase by phase (iotools.phases, diagnosis.phases)."""
import numpy as np
import pandas as pd
import pytest

from nodeforce.diagnosis.phases import phase_errors, worsened
from nodeforce.iotools.phases import read_phases
from nodeforce.model.errors import InputError


def write(tmp_path, text):
    path = tmp_path / "phases.csv"
    path.write_text(text)
    return path


def test_a_phase_lasts_until_the_next_one_starts(tmp_path):
    phases = read_phases(write(tmp_path, "time,phase\n2013-08-21T00:00+01:00,held at 30 C\n"
                                         "2013-08-30T00:00+01:00,pulses\n"))
    assert [p.name for p in phases] == ["held at 30 C", "pulses"]
    assert phases[0].end == phases[1].start and phases[1].end is None
    times = pd.date_range("2013-08-29T23:00+01:00", periods=3, freq="1h")
    assert list(phases[0].mask(times)) == [True, False, False]
    assert list(phases[1].mask(times)) == [False, True, True]


@pytest.mark.parametrize("text, column", [
    ("start,phase\n2013-08-21T00:00+01:00,a\n", "time"),
    ("time,name\n2013-08-21T00:00+01:00,a\n", "phase"),
    ("time,phase\n2013-08-21T00:00,a\n", "time"),
    ("time,phase\n2013-08-22T00:00+01:00,a\n2013-08-21T00:00+01:00,b\n", "time"),
    ("time,phase\n2013-08-21T00:00+01:00, \n", "phase"),
])
def test_a_bad_phases_file_is_refused_naming_the_column(tmp_path, text, column):
    path = write(tmp_path, text)
    with pytest.raises(InputError) as error:
        read_phases(path)
    assert str(path) in str(error.value) and column in str(error.value)


def test_errors_by_phase_by_hand_and_the_phase_made_worse(tmp_path):
    phases = read_phases(write(tmp_path, "time,phase\n2020-01-01T00:00+00:00,held\n2020-01-01T02:00+00:00,free\n"
                                         "2021-01-01T00:00+00:00,after the record\n"))
    times = pd.date_range("2020-01-01T00:00+00:00", periods=4, freq="1h")
    measured = np.array([[20.0], [20.0], [20.0], [np.nan]])
    before = np.array([[19.0], [21.0], [19.5], [0.0]])  # held: 1, 1 -> RMSE 1; free: 0.5
    after = np.array([[20.0], [20.0], [19.0], [0.0]])   # held: 0; free: 1 -> worse
    rows = phase_errors(phases, times, measured, {"before": before, "after": after})
    assert [(r["phase"], r["n"]) for r in rows] == [("held", 2), ("free", 1), ("after the record", 0)]
    assert rows[0]["rmse"] == {"before": pytest.approx(1.0), "after": pytest.approx(0.0)}
    assert rows[1]["rmse"] == {"before": pytest.approx(0.5), "after": pytest.approx(1.0)}
    assert rows[2]["rmse"] == {"before": None, "after": None}  # kept, not dropped: nothing to score
    assert worsened(rows, "before", "after") == [{"phase": "free", "before": pytest.approx(0.5),
                                                   "after": pytest.approx(1.0)}]


def test_each_zone_by_phase_by_hand_where_the_total_hides_a_room_made_worse(tmp_path):
    """Two rooms: the correction cures room a (residuals 2, 2 -> 0) and harms room b (0 -> 1, 1);
    the phase's total falls (sqrt(2) -> sqrt(1/2)) while room b's RMSE goes from 0 to 1."""
    phases = read_phases(write(tmp_path, "time,phase\n2020-01-01T00:00+00:00,held\n"))
    times = pd.date_range("2020-01-01T00:00+00:00", periods=2, freq="1h")
    measured = np.array([[22.0, 20.0], [22.0, 20.0]])
    before = np.array([[20.0, 20.0], [20.0, 20.0]])
    after = np.array([[22.0, 19.0], [22.0, 19.0]])
    [row] = phase_errors(phases, times, measured, {"before": before, "after": after}, zones=("a", "b"))
    assert row["rmse"] == {"before": pytest.approx(2 ** 0.5), "after": pytest.approx(0.5 ** 0.5)}
    assert row["zones"] == {"a": {"before": pytest.approx(2.0), "after": pytest.approx(0.0)},
                            "b": {"before": pytest.approx(0.0), "after": pytest.approx(1.0)}}
    # one zone: no per-zone rows, the total is the zone's
    [alone] = phase_errors(phases, times, measured[:, :1], {"before": before[:, :1]}, zones=("a",))
    assert "zones" not in alone
