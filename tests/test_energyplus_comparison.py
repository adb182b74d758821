"""benchmarks/energyplus_comparison.py, without EnergyPlus: EnergyPlus's face names paired with
the converted building's nodes (every surface of the IDF once, none dropped silently), its
interval-end timestamps, the hourly means of its steps, their alignment with nodeforce's samples,
and the RMSE and mean difference on series made by hand."""
import re

import idfkit
import numpy as np
import pandas as pd
import pytest

from benchmarks.energyplus_comparison import at_steps, differences, face_nodes, hourly_means, interval_ends, paired
from nodeforce.api import convert_idf
from tests.test_energyplus_reading import MULTIZONE

# every heat transfer surface the IDF declares, read from its text: EnergyPlus reports each by name
SURFACE = re.compile(r"(?m)^\s*(BuildingSurface:Detailed|FenestrationSurface:Detailed|InternalMass),\s*\n?\s*([^,!]+),")


def declared(text):
    """{surface name (upper case): (object type, zone name (upper case) or None for a window)}."""
    out, text = {}, re.sub(r"!.*", "", text)
    for m in SURFACE.finditer(text):
        kind, name = m.groups()
        fields = [f.strip() for f in text[m.start(2):].split(";")[0].split(",")]
        zone = {"BuildingSurface:Detailed": 3, "InternalMass": 2}.get(kind)
        out[name.strip().upper()] = (kind, fields[zone].upper() if zone is not None else None)
    return out


def test_every_surface_of_three_zones_pairs_with_its_own_inside_face():
    """The 21 surfaces and the furniture of three_zones.idf: each pairs with one node, no two with
    the same; a surface the converter made a component of with its component's inside face
    (depth 0) in its own zone, the second surface of a partition pair with the partition's outer
    face (its depth the partition's thickness) seen from that surface's zone."""
    text = MULTIZONE.read_text()
    surfaces = declared(text)
    assert len(surfaces) == 22
    building = convert_idf(MULTIZONE)
    nodes, unpaired = face_nodes(building, list(surfaces), idfkit.load_idf(str(MULTIZONE)))
    assert unpaired == {}
    assert set(nodes) == set(surfaces) and len(set(nodes.values())) == len(surfaces)
    by_name = {c.name.upper(): c for c in building.components}
    outer_faces = 0
    for name, node in nodes.items():
        kind, zone = surfaces[name]
        if name in by_name:
            c = by_name[name]
            assert node == c.node_ids[0] and c.depths[0] == 0.0
            if zone is not None:
                assert c.inside.zone.upper() == zone
        else:
            (c,) = [c for c in building.components if node in c.node_ids]
            assert node == c.node_ids[-1] and c.depths[-1] == pytest.approx(c.thickness)
            assert c.outside.zone.upper() == zone
            outer_faces += 1
    assert outer_faces == 3  # EAST TO WEST, CORRIDOR TO WEST, CORRIDOR TO EAST (or their partners)


def test_energyplus_made_faces_pair_by_energyplus_name_and_a_stranger_is_said(tmp_path):
    """An InternalMass given to a ZoneList: EnergyPlus reports "<zone> <mass>" (its
    CheckCreatedZoneItemName), the converter makes "<mass> <zone>"; each zone's pairs with its own
    component's inside face. A wall whose outside is a Zone: EnergyPlus reports the other side as
    "IZ-<wall>", the wall's outer face. A face the building has nothing for is returned with its
    reason."""
    text = MULTIZONE.read_text().replace("INT WALL,                !- Construction Name\n    WEST OFFICE,",
                                         "INT WALL,                !- Construction Name\n    ALL ZONES,")
    text = text.replace("WEST OFFICE,Surface,EAST TO WEST,", "WEST OFFICE,Zone,EAST OFFICE,")
    mirror = "EAST TO WEST,Wall,INT WALL,EAST OFFICE,Surface,WEST TO EAST,NoSun,NoWind,0,4,\n    0,5,3, 0,5,0, 0,0,0, 0,0,3;"
    assert mirror in text
    text = text.replace("BuildingSurface:Detailed,\n    " + mirror, "")
    assert text.count("ALL ZONES,") == MULTIZONE.read_text().count("ALL ZONES,") + 1 and "EAST TO WEST" not in text
    path = tmp_path / "listed.idf"
    path.write_text(text)
    building = convert_idf(path)
    zones = ("WEST OFFICE", "EAST OFFICE", "CORRIDOR")
    names = [f"{z} WEST FURNITURE" for z in zones] + ["IZ-WEST TO EAST", "GHOST WALL"]
    nodes, unpaired = face_nodes(building, names, idfkit.load_idf(str(path)))
    (wall,) = [c for c in building.components if c.name == "WEST TO EAST"]
    assert nodes["IZ-WEST TO EAST"] == wall.node_ids[-1] and wall.outside.zone == "EAST OFFICE"
    for z in zones:
        (c,) = [c for c in building.components if c.name.upper() == f"WEST FURNITURE {z}"]
        assert nodes[f"{z} WEST FURNITURE"] == c.node_ids[0] and c.inside.zone.upper() == z
    assert set(unpaired) == {"GHOST WALL"} and "no component" in unpaired["GHOST WALL"]


def test_interval_ends_read_energyplus_stamps():
    """EnergyPlus's stamp is the end of the interval it reports; 24:00:00 is the next midnight."""
    ends = interval_ends([" 01/01  00:10:00", " 01/01  01:00:00", " 02/28  13:40:00", " 12/31  24:00:00"], 2017)
    assert list(ends) == [pd.Timestamp("2017-01-01 00:10"), pd.Timestamp("2017-01-01 01:00"),
                          pd.Timestamp("2017-02-28 13:40"), pd.Timestamp("2018-01-01 00:00")]


def test_hourly_means_average_the_steps_ending_in_each_hour():
    """Twelve 10-min steps valued 1..12, stamped 00:10..02:00: the hour ending 01:00 is the mean of
    1..6 (3.5), the one ending 02:00 of 7..12 (9.5)."""
    ends = pd.date_range("2017-01-01 00:10", periods=12, freq="10min")
    means = hourly_means(pd.DataFrame({"A": np.arange(1.0, 13.0)}, index=ends))
    assert list(means.index) == [pd.Timestamp("2017-01-01 01:00"), pd.Timestamp("2017-01-01 02:00")]
    assert means["A"].tolist() == [3.5, 9.5]


def test_a_fine_run_is_averaged_at_the_coarse_steps_ends():
    """A 1-min run of a temperature rising 4 K an hour, and a 10-min run of the same: the fine
    run's states at the 10-min ends average over each hour to the coarse run's hourly means; the
    mean of all sixty 1-min states is 4.5 min earlier, 0.3 K below."""
    fine = pd.date_range("2017-01-01 00:01", periods=120, freq="1min")
    coarse = pd.date_range("2017-01-01 00:10", periods=12, freq="10min")
    ramp = lambda t: pd.DataFrame({"A": line(t, a=4.0)}, index=t)  # noqa: E731
    assert list(at_steps(ramp(fine), 6).index) == list(coarse)
    assert np.allclose(hourly_means(at_steps(ramp(fine), 6)), hourly_means(ramp(coarse)))
    assert np.allclose(hourly_means(ramp(coarse)) - hourly_means(ramp(fine)), 4.0 * 4.5 / 60)


def line(times, a=0.7, b=-3.0):
    """A temperature rising linearly: a K an hour from b C at 2017-01-01 00:00 (local)."""
    hours = (times - pd.Timestamp("2017-01-01")) / pd.Timedelta(hours=1)
    return a * np.asarray(hours, float) + b


def test_paired_aligns_nodeforce_samples_with_energyplus_intervals():
    """A temperature rising linearly: nodeforce samples it at 10-min steps from 00:30 (local
    standard time, tz-aware); EnergyPlus reports its state at each step's end, and its hourly
    means (the true mean of an hour is the value at its middle). Paired with the lags the
    benchmark uses, the two agree exactly; a step's misalignment shows as the slope times the step."""
    ours_t = pd.date_range("2017-01-01 00:30", "2017-01-03 23:30", freq="10min", tz="Etc/GMT+7")
    local = ours_t.tz_localize(None)
    ours = pd.DataFrame({"T1": line(local)}, index=ours_t)
    ends = pd.date_range("2017-01-01 00:10", "2017-01-04 00:00", freq="10min")
    steps = pd.DataFrame({"A": line(ends)}, index=ends)
    hour_ends = pd.date_range("2017-01-01 01:00", "2017-01-04 00:00", freq="h")
    hours = pd.DataFrame({"A": line(hour_ends - pd.Timedelta(minutes=30))}, index=hour_ends)

    T, E = paired(ours, steps, "0min")
    assert len(T) == len(ours) and differences(T["T1"], E["A"]) == pytest.approx((0.0, 0.0), abs=1e-12)
    T, E = paired(ours, hours, "30min")
    assert len(T) == 72 and differences(T["T1"], E["A"]) == pytest.approx((0.0, 0.0), abs=1e-12)
    assert list(T.index[:2]) == [pd.Timestamp("2017-01-01 00:30"), pd.Timestamp("2017-01-01 01:30")]
    T, E = paired(ours, steps, "10min")  # EnergyPlus's step read as the one before
    assert differences(T["T1"], E["A"]) == pytest.approx((0.7 / 6, -0.7 / 6))


def test_differences_on_series_made_by_hand():
    """nodeforce 0.5 K above EnergyPlus, then 1 K up and down: d = 1.5, -0.5, 1.5, -0.5, so RMSE
    sqrt((2.25 + 0.25) / 2) = sqrt(1.25) and mean 0.5."""
    E = np.array([20.0, 21.0, 19.0, 22.0])
    rmse, mean = differences(E + 0.5 + np.array([1.0, -1.0, 1.0, -1.0]), E)
    assert rmse == pytest.approx(np.sqrt(1.25)) and mean == pytest.approx(0.5)
