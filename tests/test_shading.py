"""Shading surfaces: sunlit fractions and the diffuse sky ratio against hand calculations and view
factors (docs/model.md section 4.2), and a shaded face's irradiance in a case."""
import copy

import numpy as np
import pvlib
import pytest

from nodeforce.model.building_file import parse_building
from nodeforce.model.case import prepare_case
from nodeforce.model.errors import InputError
from nodeforce.model.shading import sky_diffuse_ratio, sun_vectors, sunlit_fraction

# A south-facing window W wide and H tall in the plane y = 0, its vertices counterclockwise seen
# from the south (outside), and an overhang of depth D along its head, far wider than the window
W, H, D = 2.0, 1.5, 1.0
WINDOW = np.array([[0.0, 0.0, H], [0.0, 0.0, 0.0], [W, 0.0, 0.0], [W, 0.0, H]])
SOUTH = np.array([0.0, -1.0, 0.0])


def overhang(depth=D, half_width=50.0, height=H):
    return np.array([[-half_width, 0.0, height], [-half_width, -depth, height],
                     [W + half_width, -depth, height], [W + half_width, 0.0, height]])


def sun(altitude, off_normal):
    """Unit vector to a sun at `altitude` (deg) and `off_normal` (deg) east of south."""
    a, g = np.radians(altitude), np.radians(off_normal)
    return np.array([[np.cos(a) * np.sin(g), -np.cos(a) * np.cos(g), np.sin(a)]])


@pytest.mark.parametrize("altitude, off_normal", [(40.0, 0.0), (40.0, 30.0), (25.0, -50.0), (55.0, 10.0)])
def test_overhang_shades_the_depth_times_the_profile_angle(altitude, off_normal):
    # the shadow's edge lies D tan(Omega) below the overhang, Omega the profile angle:
    # tan(Omega) = tan(altitude) / cos(azimuth off the normal)
    drop = D * np.tan(np.radians(altitude)) / np.cos(np.radians(off_normal))
    expected = max(0.0, 1.0 - drop / H)
    assert sunlit_fraction(WINDOW, SOUTH, [overhang()], sun(altitude, off_normal))[0] == pytest.approx(expected, abs=1e-9)


def test_a_sun_behind_the_face_gives_nothing_and_a_shade_out_of_the_beam_everything():
    behind = sun(30.0, 120.0)  # north-east of the wall
    assert sunlit_fraction(WINDOW, SOUTH, [overhang()], behind)[0] == 0.0
    assert sunlit_fraction(WINDOW, SOUTH, [], behind)[0] == 0.0
    # a fin 10 m east of the window, the sun in the south-west: its shadow falls further east
    fin = np.array([[W + 10, 0, -5], [W + 10, -2, -5], [W + 10, -2, 5], [W + 10, 0, 5]])
    assert sunlit_fraction(WINDOW, SOUTH, [fin], sun(30.0, -40.0))[0] == 1.0
    # a shade behind the wall's plane casts no shadow on its outside
    assert sunlit_fraction(WINDOW, SOUTH, [overhang() * [1, -1, 1]], sun(40.0, 0.0))[0] == 1.0


def test_a_fin_and_an_overhang_shade_their_union_not_their_sum():
    altitude, off_normal, fin_depth = 40.0, -30.0, 0.8  # the sun in the south-west
    # a fin on the window's west edge (x = 0), tall beyond the window, throws a strip of width
    # fin_depth tan(30 deg) over the full height; the overhang a strip of height D tan(Omega) over
    # the full width; they overlap in the corner
    fin = np.array([[0, 0, -10], [0, -fin_depth, -10], [0, -fin_depth, 10], [0, 0, 10]])
    strip = fin_depth * np.tan(np.radians(30.0))
    drop = D * np.tan(np.radians(altitude)) / np.cos(np.radians(30.0))
    shaded = strip * H + W * drop - strip * drop
    got = sunlit_fraction(WINDOW, SOUTH, [overhang(), fin], sun(altitude, off_normal))[0]
    assert got == pytest.approx(1.0 - shaded / (W * H), abs=1e-9)
    alone = [sunlit_fraction(WINDOW, SOUTH, [s], sun(altitude, off_normal))[0] for s in (overhang(), fin)]
    assert got > alone[0] + alone[1] - 1.0 + 0.05  # the sum would count the corner twice


def test_sun_vectors_give_pvlibs_angle_of_incidence():
    zenith, azimuth = np.array([10.0, 45.0, 80.0, 60.0]), np.array([90.0, 180.0, 250.0, 10.0])
    for tilt, face_azimuth in ((90.0, 180.0), (30.0, 100.0), (0.0, 0.0)):
        t, a = np.radians(tilt), np.radians(face_azimuth)
        normal = np.array([np.sin(t) * np.sin(a), np.sin(t) * np.cos(a), np.cos(t)])
        expected = np.cos(np.radians(pvlib.irradiance.aoi(tilt, face_azimuth, zenith, azimuth)))
        assert np.allclose(sun_vectors(zenith, azimuth) @ normal, expected, atol=1e-12)


def test_the_sky_an_infinite_overhang_leaves_is_its_view_factor():
    # a vertical strip of height H under a plate of depth D along its head: by Hottel's crossed
    # strings the strip sees the plate with F = (H + D - sqrt(H^2 + D^2)) / (2 H), out of the half
    # (1 + cos 90) / 2 of its view that is sky, so it keeps 1 - 2 F of the isotropic sky
    expected = 1.0 - (H + D - np.hypot(H, D)) / H
    wide = overhang(half_width=1000.0)
    assert sky_diffuse_ratio(WINDOW, SOUTH, [wide], altitudes=90, azimuths=360) == pytest.approx(expected, abs=1e-4)
    # EnergyPlus's 6 x 24 patches, within their discretisation (15 deg steps)
    assert sky_diffuse_ratio(WINDOW, SOUTH, [wide]) == pytest.approx(expected, abs=0.005)
    assert sky_diffuse_ratio(WINDOW, SOUTH, []) == 1.0


def shaded_cell(testcell_data, shade, faces=("window",)):
    data = copy.deepcopy(testcell_data)
    window = next(c for c in data["components"] if c["name"] == "window")
    window["vertices"] = [[0.0, 0.0, 0.8], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.8]]
    data["shading"] = [{"name": "canopy", "vertices": shade, "faces": list(faces)}]
    return data


def test_a_window_under_an_endless_canopy_gets_only_the_ground_s_sun(testcell_data, testcell, weather):
    # a horizontal plate at the window's head reaching 10 km out and across hides all the sky
    # and the sun (but within 0.005 deg of the horizon): the window keeps the ground's reflection,
    # rho_g ghi (1 - cos 90) / 2; every other face is computed as without the canopy, to the bit
    canopy = [[-1e4, 0.0, 0.8], [-1e4, -1e4, 0.8], [1e4, -1e4, 0.8], [1e4, 0.0, 0.8]]
    building = parse_building(shaded_cell(testcell_data, canopy))
    week = weather.loc["2001-06-10":"2001-06-16"]
    shaded, plain = prepare_case(building, week), prepare_case(testcell, week)
    column = shaded.input_names.index("I_window")
    assert shaded.times.equals(week.index)
    assert np.allclose(shaded.U[:, column], 0.2 * week["ghi"].to_numpy(float) / 2, atol=0.5)
    others = [k for k, name in enumerate(shaded.input_names) if name != "I_window"]
    assert np.array_equal(shaded.U[:, others], plain.U[:, others])
    assert plain.U[:, column].max() > 100.0 + shaded.U[:, column].max()


def test_shading_a_face_without_vertices_or_facing_away_is_refused(testcell_data):
    data = shaded_cell(testcell_data, [[0, 0, 1], [0, -1, 1], [1, -1, 1]], faces=("window", "roof"))
    with pytest.raises(InputError, match=r"shading\[0\]\.faces.*'roof' declares no vertices"):
        parse_building(data)
    data = shaded_cell(testcell_data, [[0, 0, 1], [0, -1, 1], [1, -1, 1]])
    window = next(c for c in data["components"] if c["name"] == "window")
    window["vertices"] = window["vertices"][::-1]  # clockwise from outside: facing north
    with pytest.raises(InputError, match=r"components\[6\]\.vertices: face tilt 90\.0 deg, azimuth 0\.0 deg"):
        parse_building(data)


def test_a_face_looking_straight_down_keeps_its_whole_sky_ratio():
    """A soffit (a horizontal face looking down) sees no sky patch above the horizon: its diffuse
    ratio is 1, nothing to shade, where the patches' weighted mean would divide 0 by 0."""
    soffit = [(0.0, 0.0, 3.0), (0.0, 1.0, 3.0), (2.0, 1.0, 3.0), (2.0, 0.0, 3.0)]
    shade = [(0.0, -1.0, 2.0), (2.0, -1.0, 2.0), (2.0, 2.0, 2.0), (0.0, 2.0, 2.0)]
    assert sky_diffuse_ratio(soffit, np.array([0.0, 0.0, -1.0]), [shade]) == 1.0
