"""Sky temperature and incident solar against hand calculations (docs/model.md section 4)."""

import numpy as np
import pandas as pd
import pvlib
import pytest

from nodeforce.model.solar import (energyplus_sky, energyplus_sun, incident_irradiance, sky_temperature,
                                   solar_position, transmitted_irradiance)

SIGMA = 5.670374419e-8


def test_swinbank_by_hand():
    # 0.0552 * 293.15^1.5 = 0.0552 * 293.15 * 17.12163 = 277.060 K, i.e. 3.910 C
    assert sky_temperature(np.array([20.0]))[0] == pytest.approx(3.910, abs=1e-3)


def test_infrared_is_the_inverse_of_black_body_emission():
    t_sky = np.array([-30.0, 0.0, 10.0, 25.0])
    ir_h = SIGMA * (t_sky + 273.15) ** 4
    assert np.allclose(sky_temperature(np.full(4, 99.0), ir_h=ir_h), t_sky, atol=1e-9)


def test_given_sky_temperature_wins_and_gaps_are_not_filled_from_another_source():
    t_sky = np.array([5.0, np.nan])
    ir_h = np.array([300.0, 300.0])
    got = sky_temperature(np.array([20.0, 20.0]), ir_h=ir_h, T_sky=t_sky)
    assert got[0] == 5.0 and np.isnan(got[1])
    from_ir = sky_temperature(np.array([20.0, 20.0]), ir_h=np.array([np.nan, 300.0]))
    assert np.isnan(from_ir[0]) and from_ir[1] == pytest.approx((300.0 / SIGMA) ** 0.25 - 273.15)


def test_horizontal_surface_receives_global_horizontal():
    times = pd.date_range("2021-03-10T07:30-05:00", periods=10, freq="1h")
    position = solar_position(times, 25.8, -80.27, 2.0)
    cos_z = np.cos(np.radians(position["apparent_zenith"].to_numpy()))
    dni = np.linspace(100.0, 800.0, 10)
    dhi = np.linspace(50.0, 150.0, 10)
    ghi = dhi + dni * cos_z  # closure, so the tilted-frame sum must give ghi back
    got = incident_irradiance(position, ghi, dni, dhi, tilt=0.0, azimuth=180.0, albedo=0.3)
    assert np.allclose(got, ghi, rtol=1e-12)


def test_south_vertical_wall_at_solar_noon_by_hand():
    lat, lon, alt = 25.8, -80.27, 2.0
    day = pd.DatetimeIndex([pd.Timestamp("2021-01-15", tz="Etc/GMT+5")])
    noon = pvlib.solarposition.sun_rise_set_transit_spa(day, lat, lon)["transit"]
    times = pd.DatetimeIndex(noon)
    position = solar_position(times, lat, lon, alt)
    zenith = position["apparent_zenith"].iloc[0]
    assert position["azimuth"].iloc[0] == pytest.approx(180.0, abs=0.05)
    # Mid-January at 25.8 N: declination about -21 deg, so the noon zenith is about 47 deg.
    assert zenith == pytest.approx(25.8 + 21.2, abs=1.0)
    ghi, dni, dhi, albedo = 600.0, 800.0, 80.0, 0.2
    expected = dni * np.sin(np.radians(zenith)) + dhi / 2 + albedo * ghi / 2
    got = incident_irradiance(position, [ghi], [dni], [dhi], tilt=90.0, azimuth=180.0, albedo=albedo)
    assert got[0] == pytest.approx(expected, rel=1e-4)


def test_north_wall_gets_no_beam_from_a_southern_sun():
    lat, lon = 25.8, -80.27
    times = pd.DatetimeIndex([pd.Timestamp("2021-01-15T12:20", tz="Etc/GMT+5")])
    position = solar_position(times, lat, lon, 2.0)
    got = incident_irradiance(position, [600.0], [800.0], [80.0], tilt=90.0, azimuth=0.0, albedo=0.2)
    assert got[0] == pytest.approx(80.0 / 2 + 0.2 * 600.0 / 2)


def test_a_sun_below_the_horizon_casts_no_beam():
    """Denver, 4 March 2017 at 18:00 MST: the sun 2.3 deg below the horizon, in the west-southwest,
    with an EPW hour's dni interpolated there (24.5 W/m2). A west wall faces the sun's azimuth,
    so that cos theta = cos(2.3 deg) cos(83 deg) > 0 on a south one: neither gets a beam, only
    the ground's and the sky's diffuse, as a north wall does."""
    times = pd.DatetimeIndex([pd.Timestamp("2017-03-04T18:00", tz="Etc/GMT+7")])
    position = energyplus_sun(times, 39.83, -104.65, -7.0)
    assert -3.0 < position["elevation"].iloc[0] < -2.0
    ghi, dni, dhi = [16.5], [24.5], [14.5]
    north = incident_irradiance(position, ghi, dni, dhi, 90.0, 0.0, 0.2)
    for azimuth in (180.0, 270.0):
        assert incident_irradiance(position, ghi, dni, dhi, 90.0, azimuth, 0.2) == pytest.approx(north)
    assert north[0] == pytest.approx(14.5 / 2 + 0.2 * 16.5 / 2)


def test_night_missing_and_negative_irradiance_give_zero():
    times = pd.DatetimeIndex(pd.to_datetime(["2021-06-01T00:00-05:00", "2021-06-01T12:00-05:00",
                                             "2021-06-01T23:00-05:00"]))
    position = solar_position(times, 25.8, -80.27, 2.0)
    ghi = np.array([0.0, np.nan, -3.0])
    dni = np.array([0.0, 500.0, -1.0])
    dhi = np.array([0.0, 100.0, -3.0])
    for tilt, azimuth in ((0.0, 180.0), (90.0, 90.0), (45.0, 270.0)):
        got = incident_irradiance(position, ghi, dni, dhi, tilt, azimuth, 0.2)
        assert np.array_equal(got, [0.0, 0.0, 0.0])


def test_transmitted_sun_by_hand():
    """A horizontal glazing, the sun 60 deg from the zenith: the direct part dni cos 60 times the
    table's factor at 60 deg, the sky's diffuse times the diffuse factor; with the sun below the
    horizon the diffuse alone (a dni the weather still gives then is not sun)."""
    position = pd.DataFrame({"apparent_zenith": [60.0, 95.0], "azimuth": [180.0, 180.0]})
    sun = transmitted_irradiance(position, ghi=[600.0, 50.0], dni=[1000.0, 200.0], dhi=[100.0, 50.0], tilt=0.0,
                                 azimuth=180.0, albedo=0.2, angles=[0, 40, 60, 80], factors=[1, 0.98, 0.8, 0.3],
                                 diffuse=0.85)
    assert sun == pytest.approx([0.8 * 1000 * 0.5 + 0.85 * 100, 0.85 * 50], rel=1e-9)


def test_a_grid_asked_again_gets_pvlibs_positions_as_its_own_copy():
    times = pd.date_range("2001-06-21", periods=96, freq="15min", tz="Etc/GMT+5")
    first = solar_position(times, 25.8, -80.3, 2.0)
    first["azimuth"] = 0.0  # the caller's to change
    again = solar_position(times.rename("time"), 25.8, -80.3, 2.0)
    direct = pvlib.solarposition.get_solarposition(times, 25.8, -80.3, 2.0)
    assert np.array_equal(again.to_numpy(), direct.to_numpy()) and list(again.columns) == list(direct.columns)
    assert again.index.equals(times) and again.index.name == "time"
    south = solar_position(times, -25.8, -80.3, 2.0)  # another site, the same times
    assert np.abs(south["apparent_zenith"] - direct["apparent_zenith"]).max() > 10.0
    later = solar_position(times + pd.Timedelta(hours=6), 25.8, -80.3, 2.0)
    assert np.array_equal(later["azimuth"].to_numpy()[:72], direct["azimuth"].to_numpy()[24:])


# EnergyPlus 25.2.0's own "Site Solar Altitude Angle" and "Site Solar Azimuth Angle" (deg) at these
# 10-min steps' ends, local standard time, of a 2017 run on the Denver-Aurora-Buckley TMY3 EPW that
# pyenergyplus-lbnl 26.1.0 ships (its LOCATION: 39.72 N, 104.75 W, UTC-7), 6 steps an hour
ENERGYPLUS_DENVER_SUN = [("2017-01-15 09:00", 14.866080, 135.109521), ("2017-03-21 12:00", 50.210615, 177.458042),
                         ("2017-04-20 07:10", 20.950322, 92.651633), ("2017-06-21 16:00", 37.445355, 270.877224),
                         ("2017-08-05 18:30", 6.242534, 287.174183), ("2017-09-22 10:00", 43.297915, 139.826776),
                         ("2017-11-03 13:20", 30.920856, 207.670284), ("2017-12-21 12:00", 26.794632, 180.885433)]


def test_energyplus_sun_is_energypluss_own():
    times = pd.DatetimeIndex([t for t, _, _ in ENERGYPLUS_DENVER_SUN]).tz_localize("Etc/GMT+7")
    sun = solar_position(times, 39.72, -104.75, 1726.0, "energyplus", -7.0)
    assert sun["elevation"].to_numpy() == pytest.approx([a for _, a, _ in ENERGYPLUS_DENVER_SUN], abs=1e-4)
    assert sun["azimuth"].to_numpy() == pytest.approx([z for _, _, z in ENERGYPLUS_DENVER_SUN], abs=1e-4)
    assert np.array_equal(sun["apparent_zenith"], 90.0 - sun["elevation"])  # no refraction
    # the same instants on another clock: the position is the instant's, not the clock's
    again = energyplus_sun(times.tz_convert("UTC"), 39.72, -104.75, -7.0)
    assert np.array_equal(again.to_numpy(), sun.to_numpy())


@pytest.mark.parametrize("latitude, longitude, offset", [(52.0, 13.4, 1.0), (-33.9, 18.4, 2.0), (1.3, 103.8, 8.0)])
def test_energyplus_sun_is_spa_to_half_a_degree(latitude, longitude, offset):
    # each day's declination held from the day's start (it moves up to 0.4 deg a day) and the
    # series' fit put EnergyPlus's sun within half a degree of NREL's SPA (its true, unrefracted
    # zenith), the sun's direction within that too, over a year
    times = pd.date_range("2019-01-01 00:30", periods=8760, freq="h", tz="UTC")
    ours = energyplus_sun(times, latitude, longitude, offset)
    spa = pvlib.solarposition.get_solarposition(times, latitude, longitude, 0.0)
    up = spa["elevation"].to_numpy() > 2.0
    assert np.abs(ours["zenith"].to_numpy() - spa["zenith"].to_numpy())[up].max() < 0.5

    def vector(frame):
        z, a = np.radians(frame["zenith"].to_numpy()), np.radians(frame["azimuth"].to_numpy())
        return np.stack([np.sin(z) * np.sin(a), np.sin(z) * np.cos(a), np.cos(z)])
    cosine = np.sum(vector(ours) * vector(spa), axis=0)[up]
    assert np.degrees(np.arccos(np.clip(cosine, -1, 1))).max() < 0.5


def test_energyplus_sky_by_hand():
    # Z = 60 deg = 1.047198 rad, dni 600, dhi 100 W/m2, sea level: kappa = 1.041 Z^3 = 1.195465,
    # epsilon = (700 / 100 + 1.195465) / 2.195465 = 3.73293, the bin 2.8..4.5 (F11 1.1326077,
    # F12 -1.2367284, F13 -0.4118494; F21 0.2877813, F22 -0.8230357, F23 0.0558651); the air mass
    # 1 / cos Z = 2, Delta = 100 x 2 / 1353 = 0.147820:
    # F1 = 1.1326077 - 1.2367284 x 0.147820 - 0.4118494 x 1.047198 = 0.518507
    # F2 = 0.2877813 - 0.8230357 x 0.147820 + 0.0558651 x 1.047198 = 0.224621
    # a wall at cos theta 0.5: dome 100 (0.5 (1 - F1) + F2) = 46.537, circumsolar 100 F1 0.5 / 0.5
    dome, circumsolar = energyplus_sky(np.array([60.0]), np.array([0.5]), np.array([600.0]), np.array([100.0]),
                                       tilt=90.0, altitude=0.0)
    assert dome[0] == pytest.approx(46.537, abs=2e-3)
    assert circumsolar[0] == pytest.approx(51.851, abs=2e-3)
    # at 1000 m the air mass is 0.9 x 2: Delta 0.133038, F1 0.518507 + 1.2367284 x 0.014782
    _, high = energyplus_sky(np.array([60.0]), np.array([0.5]), np.array([600.0]), np.array([100.0]),
                             tilt=90.0, altitude=1000.0)
    assert high[0] == pytest.approx(100 * (0.518507 + 1.2367284 * 0.014782), abs=2e-3)


def test_energyplus_sky_gives_a_horizontal_face_the_whole_diffuse_horizontal():
    """On a horizontal face the dome keeps dhi (1 - F1) and the circumsolar disc dhi F1 cos Z / cos Z:
    whatever the brightening, the sum is the diffuse horizontal irradiance."""
    rng = np.random.default_rng(3)
    zenith = rng.uniform(0.0, 84.0, 200)
    dhi = rng.uniform(5.0, 400.0, 200)
    dni = rng.uniform(0.0, 1000.0, 200)
    dome, circumsolar = energyplus_sky(zenith, np.cos(np.radians(zenith)), dni, dhi, tilt=0.0, altitude=1609.0)
    assert np.allclose(dome + circumsolar, dhi, rtol=1e-12)
    assert (circumsolar > 0).any() and (circumsolar < dhi).all()


def test_energyplus_sky_is_pvlibs_perez_on_energyplus_air_mass():
    """pvlib's Perez (1990, all-sites composite coefficients), given EnergyPlus's air mass and its
    1353 W/m2, is an independent formulation of the same sky: pvlib's coefficients are the paper's,
    to 3 decimals, EnergyPlus's those Perez gave it to 7, so the two agree to their rounding,
    0.0005 (1 + Delta + Z) on F1 and F2, some 0.2 % of dhi at most under a sun within 70 deg."""
    rng = np.random.default_rng(5)
    n = 300
    zenith, sun_azimuth = rng.uniform(0.0, 70.0, n), rng.uniform(0.0, 360.0, n)
    dhi, dni = rng.uniform(5.0, 400.0, n), rng.uniform(0.0, 1000.0, n)
    tilt, azimuth = 75.0, 200.0
    cos_theta = pvlib.irradiance.aoi_projection(tilt, azimuth, zenith, sun_azimuth)
    dome, circumsolar = energyplus_sky(zenith, cos_theta, dni, dhi, tilt=tilt, altitude=1609.0)
    mass = (1 - 0.1 * 1.609) / np.cos(np.radians(zenith))
    theirs = pvlib.irradiance.perez(tilt, azimuth, dhi, dni, 1353.0, zenith, sun_azimuth, mass,
                                    model="allsitescomposite1990")
    assert (np.abs(dome + circumsolar - theirs) <= 0.002 * dhi).all()
    assert np.abs(dome + circumsolar - theirs).max() > 1e-6  # two tables, not one


def test_energyplus_sky_is_dark_with_the_sun_down():
    dome, circumsolar = energyplus_sky(np.array([95.0, 60.0]), np.array([0.3, 0.3]), np.array([0.0, 0.0]),
                                       np.array([20.0, 0.0]), tilt=90.0, altitude=0.0)
    assert (dome == 0).all() and (circumsolar == 0).all()


def test_declared_sky_changes_only_the_skys_diffuse():
    """Under EnergyPlus's sky a face gets the isotropic sky's direct and ground-reflected sun and
    `energyplus_sky`'s diffuse in place of the isotropic one: the difference of the two totals is
    the difference of the two skies alone."""
    times = pd.date_range("2017-06-21T06:30-07:00", periods=12, freq="1h")
    position = solar_position(times, 39.76, -104.86, 1609.0)
    dni, dhi = np.linspace(100.0, 800.0, 12), np.linspace(150.0, 60.0, 12)
    ghi = dhi + dni * np.cos(np.radians(position["apparent_zenith"].to_numpy()))
    iso = incident_irradiance(position, ghi, dni, dhi, 90.0, 90.0, 0.2)
    ep = incident_irradiance(position, ghi, dni, dhi, 90.0, 90.0, 0.2, sky_model="energyplus", altitude=1609.0)
    zenith = position["zenith"].to_numpy()
    cos_theta = pvlib.irradiance.aoi_projection(90.0, 90.0, zenith, position["azimuth"].to_numpy())
    dome, circumsolar = energyplus_sky(zenith, cos_theta, dni, dhi, 90.0, 1609.0)
    assert np.allclose(ep - iso, dome + circumsolar - dhi / 2, atol=1e-9)
    assert (ep[:4] > iso[:4]).all()  # a morning sun on an east wall: its circumsolar disc is in view
