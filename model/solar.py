"""Sky temperature and solar irradiance on the outside faces of a building (docs/model.md section 4).

Pure functions on numpy arrays and pandas indexes, no I/O. The sun position is computed once for
a time grid (`solar_position`) and reused for every surface (`incident_irradiance`), because it is
by far the most expensive part and does not depend on the surface; the last few grids' positions
are kept, since a record is prepared for several buildings of one site.
"""

import threading
from collections import OrderedDict

import numpy as np
import pandas as pd
import pvlib

#: Stefan-Boltzmann constant, W/m2/K4 (CODATA 2018, exact).
STEFAN_BOLTZMANN = 5.670374419e-8

#: Offset between degrees Celsius and kelvin, K.
ZERO_CELSIUS = 273.15


def sky_temperature(T_out, ir_h=None, T_sky=None):
    """Effective sky temperature for long-wave exchange, degrees C.

    Chooses its source by which input is given, never mixing sources element by element: a
    missing `T_sky` or `ir_h` sample gives a missing (NaN) sky temperature rather than one from
    another formula, so gaps in a measured column stay visible.

    Parameters
    ----------
    T_out : array_like
        Outdoor air temperature, degrees C. Used only when neither other input is given.
    ir_h : array_like, optional
        Horizontal infrared irradiance from the sky, W/m2.
    T_sky : array_like, optional
        Measured or given sky temperature, degrees C. Takes precedence over `ir_h`.

    Returns
    -------
    numpy.ndarray
        Sky temperature, degrees C: `T_sky` as given; else the black-body temperature of `ir_h`,
        `(ir_h / sigma)^0.25 - 273.15`; else Swinbank's clear-sky estimate
        `0.0552 (T_out + 273.15)^1.5 - 273.15`.
    """
    if T_sky is not None:
        return np.asarray(T_sky, dtype=float)
    if ir_h is not None:
        return (np.asarray(ir_h, dtype=float) / STEFAN_BOLTZMANN) ** 0.25 - ZERO_CELSIUS
    return 0.0552 * (np.asarray(T_out, dtype=float) + ZERO_CELSIUS) ** 1.5 - ZERO_CELSIUS


def measured_irradiance(component, columns):
    """The weather column measuring the irradiance on a component's outside face, or None.

    Parameters
    ----------
    component : Component
        An exterior component of the building.
    columns : collection of str
        The weather's columns.

    Returns
    -------
    str or None
        The face's own `irradiance` column when the building names one (several faces may share
        it); else `I_<component name>` when the weather has it (W/m2); None when the face's
        irradiance is to be computed from `ghi`, `dni`, `dhi` (`incident_irradiance`).
    """
    if component.outside.irradiance:
        return component.outside.irradiance
    name = f"I_{component.name}"
    return name if name in columns else None


def solar_position(times, latitude, longitude, altitude, model="spa", utc_offset=None):
    """Sun position at each sample time, to be shared by all surfaces of a building.

    Parameters
    ----------
    times : pandas.DatetimeIndex
        Sample times, timezone-aware. The position is the instantaneous one at each time, so
        hour-averaged irradiance should be stamped at the middle of its hour (see nodeforce.iotools.hourly).
    latitude, longitude : float
        Site, degrees (north and east positive).
    altitude : float
        Site altitude, m.
    model : str
        One of `SUN_MODELS`: "spa", pvlib's `get_solarposition` (NREL's SPA, the apparent zenith
        refracted); "energyplus", EnergyPlus's own daily series (`energyplus_sun`).
    utc_offset : float
        The site's standard time less UTC, h: the meridian EnergyPlus's hour angle counts from
        (needed by "energyplus" only).

    Returns
    -------
    pandas.DataFrame
        Indexed by `times`, pvlib's columns; those used here are `zenith`, `apparent_zenith` and
        `azimuth`, degrees (azimuth clockwise from north). A copy: the caller may change it.
    """
    # pvlib's SPA costs some 10 us a time: a record prepared for the building as written and as
    # corrected, or a synthetic truth run at several fault sizes, asks for the same grid again
    key = (times.asi8.tobytes(), str(times.tz), float(latitude), float(longitude), float(altitude), model, utc_offset)
    with _KEPT_LOCK:  # a Dask worker runs tasks in threads
        position = _POSITIONS.get(key)
        if position is not None:
            _POSITIONS.move_to_end(key)
    if position is None:
        if model == "energyplus":
            position = energyplus_sun(times, latitude, longitude, utc_offset)
        else:
            position = pvlib.solarposition.get_solarposition(times, latitude, longitude, altitude)
        with _KEPT_LOCK:
            _POSITIONS[key] = position
            while len(_POSITIONS) > POSITIONS_KEPT:
                _POSITIONS.popitem(last=False)
    position = position.copy()
    position.index = times
    return position


#: How a site may place the sun (`site.solar_position`): NREL's SPA through pvlib, or EnergyPlus's series.
SUN_MODELS = ("spa", "energyplus")

#: EnergyPlus's Fourier series in X = 2 pi d / 366 of the day of the year d, each day's sine of the
#: sun's declination (-) and equation of time (h), coefficients in the order of `_day_series`
#: (WeatherManager.cc CalculateDailySolarCoeffs, SolarShading.cc SUN3; Engineering Reference,
#: "Solar Position"; fitted at USACERL to Threlkeld's tables).
ENERGYPLUS_SINE_DECLINATION = (0.00561800, 0.0657911, -0.392779, 0.00064440, -0.00618495, -0.00010101,
                               -0.00007951, -0.00011691, 0.00002096)
ENERGYPLUS_EQUATION_OF_TIME = (0.00021971, -0.122649, 0.00762856, -0.156308, -0.0530028, -0.00388702,
                               -0.00123978, -0.00270502, -0.00167992)


def _day_series(coefficients, x):
    """sum_k c_k f_k(x) over 1, sin x, cos x, sin 2x, cos 2x, sin 3x, cos 3x, sin 4x, cos 4x, the
    order of EnergyPlus's coefficients (x in rad)."""
    harmonics = (np.ones_like(x), np.sin(x), np.cos(x), np.sin(2 * x), np.cos(2 * x), np.sin(3 * x), np.cos(3 * x),
                 np.sin(4 * x), np.cos(4 * x))
    return sum(c * f for c, f in zip(coefficients, harmonics))


def energyplus_sun(times, latitude, longitude, utc_offset):
    """The sun as EnergyPlus places it (docs/model.md section 4, "Sun position"): each day's
    declination and equation of time from its Fourier series of the day of the year
    (`ENERGYPLUS_SINE_DECLINATION`, `ENERGYPLUS_EQUATION_OF_TIME`), held over the day, and the
    hour angle of each time's local standard clock t (h since the day's midnight; a time at
    midnight ends the day before, as EnergyPlus stamps it 24:00),

        H = 15 (12 - (t + EoT)) + (15 utc_offset - longitude)        (deg, + before noon)

    no refraction. `times` tz-aware, `latitude` and `longitude` deg (north, east), `utc_offset`
    h. A DataFrame indexed by `times` with pvlib's columns (deg; the equation of time in min)."""
    clock = times.tz_convert("UTC").tz_localize(None) + pd.Timedelta(hours=utc_offset)
    day = clock - pd.Timedelta(1, "ns")
    x = 2.0 * np.pi / 366.0 * day.day_of_year.to_numpy(float)
    hours = (clock - day.normalize()).total_seconds().to_numpy() / 3600.0
    sin_d = _day_series(ENERGYPLUS_SINE_DECLINATION, x)
    cos_d = np.sqrt(1.0 - sin_d ** 2)
    equation = _day_series(ENERGYPLUS_EQUATION_OF_TIME, x)
    hour_angle = np.radians(15.0 * (12.0 - (hours + equation)) + (15.0 * utc_offset - longitude))
    phi = np.radians(latitude)
    up = sin_d * np.sin(phi) + cos_d * np.cos(phi) * np.cos(hour_angle)
    east = cos_d * np.sin(hour_angle)
    north = sin_d * np.cos(phi) - cos_d * np.sin(phi) * np.cos(hour_angle)
    elevation = np.degrees(np.arcsin(np.clip(up, -1.0, 1.0)))
    return pd.DataFrame({"apparent_zenith": 90.0 - elevation, "zenith": 90.0 - elevation,
                         "apparent_elevation": elevation, "elevation": elevation,
                         "azimuth": np.degrees(np.arctan2(east, north)) % 360.0,
                         "equation_of_time": 60.0 * equation}, index=times)


#: How many time grids' sun positions `solar_position` keeps (the least recently asked dropped).
POSITIONS_KEPT = 4
_POSITIONS = OrderedDict()
_KEPT_LOCK = threading.Lock()


def incident_irradiance(position, ghi, dni, dhi, tilt, azimuth, albedo, sunlit=1.0, sky=1.0, sky_model="isotropic",
                        altitude=0.0):
    """Solar irradiance incident on a plane surface, W/m2.

    Parameters
    ----------
    position : pandas.DataFrame
        Output of `solar_position` for the same sample times as the irradiance arrays.
    ghi, dni, dhi : array_like
        Global horizontal, direct normal and diffuse horizontal irradiance, W/m2.
    tilt : float
        Surface tilt from horizontal, degrees (0 faces up, 90 vertical, 180 faces down).
    azimuth : float
        Direction the surface faces, degrees clockwise from north (180 = south).
    albedo : float
        Ground reflectance, 0..1.
    sunlit, sky : array_like or float
        The face's sunlit fraction at each time and the part of its sky diffuse it gets, both
        1 for a face no shading surface shades (`model.shading`, docs/model.md section 4.2).
    sky_model : str
        How the sky's diffuse sun spreads over the dome (`SKY_MODELS`): "isotropic" (pvlib's
        isotropic sky) or "energyplus" (EnergyPlus's anisotropic sky, `energyplus_sky`).
    altitude : float
        Site altitude, m: the anisotropic sky's air mass reads it.

    Returns
    -------
    numpy.ndarray
        `direct sunlit + (sky_diffuse sky + ground_diffuse)`, plus the circumsolar part times
        `sunlit` under the anisotropic sky (W/m2; pvlib's isotropic `poa_global` where unshaded
        and isotropic), with NaN and negative values set to 0: a missing weather sample
        contributes no sun (docs/model.md section 4).
    """
    direct, diffuse, circumsolar, ground = _sky_parts(position, ghi, dni, dhi, tilt, azimuth, albedo, sky_model,
                                                      altitude)
    poa = direct * sunlit + (diffuse * sky + ground)
    if circumsolar is not None:
        poa = poa + circumsolar * sunlit
    return np.where(np.isfinite(poa) & (poa > 0.0), poa, 0.0)


#: The skies a site may declare (`site.sky_diffuse`): isotropic, or EnergyPlus's anisotropic one.
SKY_MODELS = ("isotropic", "energyplus")

#: EnergyPlus's Perez (1990) sky: upper limits of the clearness bins (-) and, a row a bin, the
#: circumsolar (F11, F12, F13) and horizon (F21, F22, F23) coefficients (SolarShading.cc,
#: AnisoSkyViewFactors; Engineering Reference, "Sky Radiance Model").
PEREZ_EPSILON_LIMITS = np.array([1.065, 1.23, 1.5, 1.95, 2.8, 4.5, 6.2])
PEREZ_F1 = np.array([[-0.0083117, 0.5877285, -0.0620636], [0.1299457, 0.6825954, -0.1513752],
                     [0.3296958, 0.4868735, -0.2210958], [0.5682053, 0.1874525, -0.2951290],
                     [0.8730280, -0.3920403, -0.3616149], [1.1326077, -1.2367284, -0.4118494],
                     [1.0601591, -1.5999137, -0.3589221], [0.6777470, -0.3272588, -0.2504286]])
PEREZ_F2 = np.array([[-0.0596012, 0.0721249, -0.0220216], [-0.0189325, 0.0659650, -0.0288748],
                     [0.0554140, -0.0639588, -0.0260542], [0.1088631, -0.1519229, -0.0139754],
                     [0.2255647, -0.4620442, 0.0012448], [0.2877813, -0.8230357, 0.0558651],
                     [0.2642124, -1.1272340, 0.1310694], [0.1561313, -1.3765031, 0.2506212]])
#: The cosine of 85 deg: a sun beyond it divides the circumsolar ratio cos(theta) / cos(Z) by it.
COS_85 = 0.0871557


def perez_brightening(zenith, dni, dhi, altitude):
    """EnergyPlus's circumsolar and horizon brightening coefficients (F1, F2), both -, of the
    Perez (1990) sky (Engineering Reference, "Sky Radiance Model"):

        m = (1 - 0.1 H / 1000) / cos Z                       Z <= 75 deg
        m = (1 - 0.1 H / 1000) / (cos Z + 0.15 (93.9 - Z)^-1.253)   beyond (Z in deg)
        epsilon = ((dni + dhi) / dhi + 1.041 Z^3) / (1 + 1.041 Z^3)   (Z in rad)
        Delta = dhi m / 1353
        F1 = max(0, F11 + F12 Delta + F13 Z),   F2 = F21 + F22 Delta + F23 Z

    with the coefficients of epsilon's bin (`PEREZ_EPSILON_LIMITS`, `PEREZ_F1`, `PEREZ_F2`).

    Parameters
    ----------
    zenith : array_like
        The sun's true zenith angle, degrees (below 90: the sun is up).
    dni, dhi : array_like
        Direct normal and diffuse horizontal irradiance, W/m2 (dhi > 0).
    altitude : float
        Site altitude H, m.
    """
    zenith = np.asarray(zenith, dtype=float)
    dni, dhi = np.asarray(dni, dtype=float), np.asarray(dhi, dtype=float)
    z = np.radians(zenith)
    cos_z = np.cos(z)
    low = np.maximum(93.9 - zenith, 1e-9)  # Kasten's term has no value 3.9 deg below the horizon
    mass = (1.0 - 0.1 * altitude / 1000.0) / np.where(zenith <= 75.0, cos_z, cos_z + 0.15 * low ** -1.253)
    kappa = 1.041 * z ** 3
    epsilon = ((dni + dhi) / dhi + kappa) / (1.0 + kappa)
    delta = dhi * mass / 1353.0  # 1353 W/m2: EnergyPlus's mean extraterrestrial irradiance
    k = np.searchsorted(PEREZ_EPSILON_LIMITS, epsilon, side="right")
    f1 = np.maximum(0.0, PEREZ_F1[k, 0] + PEREZ_F1[k, 1] * delta + PEREZ_F1[k, 2] * z)
    f2 = PEREZ_F2[k, 0] + PEREZ_F2[k, 1] * delta + PEREZ_F2[k, 2] * z
    return f1, f2


def energyplus_sky(zenith, cos_incidence, dni, dhi, tilt, altitude):
    """The sky's diffuse sun on a face as EnergyPlus spreads it (W/m2), as two parts: the dome and
    the horizon, which the face's sky ratio R_sky shades, and the circumsolar disc, which its
    sunlit fraction shades (Engineering Reference, "Sky Radiance Model"):

        I_dome = dhi [(1 + cos beta) / 2 (1 - F1) + F2 sin beta]
        I_cs   = dhi F1 max(0, cos theta) / max(cos 85 deg, cos Z)

    (F1, F2 from `perez_brightening`; a face tilted less than 2 deg under a sun beyond 85 deg
    gets I_cs = dhi F1, as EnergyPlus forces it; both 0 where the sun is down or dhi is not
    positive, as EnergyPlus has no diffuse sun then).

    Parameters
    ----------
    zenith : array_like
        The sun's true zenith angle Z, degrees.
    cos_incidence : array_like
        Cosine of the sun's angle of incidence theta on the face, -.
    dni, dhi : array_like
        Direct normal and diffuse horizontal irradiance, W/m2.
    tilt : float
        The face's tilt beta, degrees.
    altitude : float
        Site altitude, m.
    """
    zenith, dhi = np.asarray(zenith, dtype=float), np.asarray(dhi, dtype=float)
    up = (zenith < 90.0) & (dhi > 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        f1, f2 = perez_brightening(np.where(up, zenith, 0.0), dni, np.where(up, dhi, 1.0), altitude)
    beta = np.radians(tilt)
    cos_z = np.cos(np.radians(zenith))
    ratio = np.maximum(0.0, cos_incidence) / np.maximum(COS_85, cos_z)
    if tilt < 2.0:
        ratio = np.where((ratio > 0.0) & (cos_z < COS_85), 1.0, ratio)
    dome = dhi * ((1.0 + np.cos(beta)) / 2.0 * (1.0 - f1) + f2 * np.sin(beta))
    return np.where(up, dome, 0.0), np.where(up, dhi * f1 * ratio, 0.0)


def _array(values):
    return np.asarray(values, dtype=float)


def _isotropic(position, ghi, dni, dhi, tilt, azimuth, albedo):
    """pvlib's isotropic-sky irradiance on a plane (W/m2): its `poa_global`, `poa_direct` and the
    sky's and the ground's `poa_diffuse`."""
    return pvlib.irradiance.get_total_irradiance(
        tilt, azimuth, np.asarray(position["apparent_zenith"], dtype=float),
        np.asarray(position["azimuth"], dtype=float), np.asarray(dni, dtype=float),
        np.asarray(ghi, dtype=float), np.asarray(dhi, dtype=float), albedo=albedo, model="isotropic")


def _sky_parts(position, ghi, dni, dhi, tilt, azimuth, albedo, sky_model, altitude):
    """(direct, sky diffuse, circumsolar or None, ground diffuse) W/m2 on a plane, unclipped: the
    isotropic sky's from pvlib (no circumsolar part), or EnergyPlus's anisotropic sky
    (`energyplus_sky`) in place of the sky's diffuse, the direct and the ground's kept. A sun
    below the horizon casts no beam, whatever dni the weather gives there (an hour's dni
    interpolated to a time after sunset)."""
    poa = _isotropic(position, ghi, dni, dhi, tilt, azimuth, albedo)
    up = _array(position["apparent_zenith"]) < 90.0
    direct, ground = np.where(up, _array(poa["poa_direct"]), 0.0), _array(poa["poa_ground_diffuse"])
    if sky_model == "isotropic":
        return direct, _array(poa["poa_sky_diffuse"]), None, ground
    zenith = _array(position["zenith"])
    cos_incidence = pvlib.irradiance.aoi_projection(tilt, azimuth, zenith, _array(position["azimuth"]))
    dome, circumsolar = energyplus_sky(zenith, _array(cos_incidence), dni, dhi, tilt, altitude)
    return direct, dome, circumsolar, ground


#: pvlib's decompositions of the global horizontal irradiance into its direct and diffuse parts
#: that need nothing but ghi, the sun's zenith and the time (Erbs the default, the classic one).
DECOMPOSITIONS = ("erbs", "erbs_driesse", "boland", "orgill_hollands", "louche", "disc", "dirint")


def complete_irradiance(position, ghi=None, dni=None, dhi=None, decomposition="erbs"):
    """The three horizontal components (ghi, dni, dhi, W/m2) from those a weather file has.

    Parameters
    ----------
    position : pandas.DataFrame
        Output of `solar_position` at the samples' times; its `zenith` (true, degrees) is used.
    ghi, dni, dhi : array_like or None
        Global horizontal, direct normal, diffuse horizontal irradiance (W/m2) where measured.
        ghi with at least one of the others, or dni and dhi, is needed.
    decomposition : str
        The pvlib model (one of `DECOMPOSITIONS`) that splits ghi when it is the only one.

    Returns
    -------
    (ghi, dni, dhi) as numpy arrays (W/m2), and a sentence saying what was computed (None when
    all three were given). Two components give the third by closure,
    ghi = dhi + dni cos(zenith) (pvlib's `complete_irradiance`); ghi alone is split by
    the pvlib decomposition, a modelling assumption.
    """
    given = {name: v for name, v in (("ghi", ghi), ("dni", dni), ("dhi", dhi)) if v is not None}
    if len(given) == 3:
        return ghi, dni, dhi, None
    zenith = pd.Series(np.asarray(position["zenith"], dtype=float), index=position.index)
    series = {name: pd.Series(np.asarray(v, dtype=float), index=position.index) for name, v in given.items()}
    if len(given) == 2:
        out = pvlib.irradiance.complete_irradiance(zenith, **series)
        missing = next(name for name in ("ghi", "dni", "dhi") if name not in given)
        said = (f"{missing} computed from {' and '.join(given)} by closure, ghi = dhi + dni cos(zenith) "
                "(pvlib complete_irradiance)")
    elif set(given) == {"ghi"}:
        out = decompose(series["ghi"], zenith, decomposition)
        said = (f"dni and dhi split from ghi by pvlib's {decomposition} decomposition (a modelling assumption: "
                "measured direct or diffuse irradiance would replace it; --decomposition chooses among "
                f"{', '.join(DECOMPOSITIONS)})")
    else:
        raise ValueError(f"the irradiance needs ghi, or two of ghi, dni and dhi; given: {', '.join(given) or 'none'}")
    return tuple(np.asarray(out[name], dtype=float) for name in ("ghi", "dni", "dhi")) + (said,)


def decompose(ghi, zenith, model="erbs"):
    """{"ghi", "dni", "dhi"} (W/m2) from ghi (Series, W/m2, time index) and the true solar zenith
    (Series, degrees) by one of pvlib's `DECOMPOSITIONS`; disc and dirint give dni alone, and
    dhi follows by closure."""
    function = getattr(pvlib.irradiance, model)
    times = ghi.index
    if model in ("disc", "dirint"):
        dni = function(ghi, zenith, times)
        dni = np.asarray(dni["dni"] if model == "disc" else dni, dtype=float)
        return {"ghi": ghi, "dni": dni, "dhi": np.asarray(ghi, dtype=float) - dni * np.cos(np.radians(zenith))}
    out = function(ghi, zenith, times)
    return {"ghi": ghi, "dni": out["dni"], "dhi": out["dhi"]}



def transmitted_irradiance(position, ghi, dni, dhi, tilt, azimuth, albedo, angles, factors, diffuse, sunlit=1.0,
                           sky=1.0, sky_model="isotropic", altitude=0.0):
    """The sun a glazing lets in per m2, relative to its normal-incidence transmittance (W/m2,
    docs/model.md section 4.1), or its panes absorb, relative to their normal-incidence
    absorptance, by that table: the direct sun times the factor at its angle of incidence (linear
    between the tabulated angles, 0 beyond 90 deg) plus the sky's and the ground's diffuse sun
    times the diffuse factor, under the isotropic sky

        I_t = f(theta) f_sun dni max(cos theta, 0) + f_d [R_sky dhi (1 + cos beta) / 2 + ghi rho_g (1 - cos beta) / 2]

    and under EnergyPlus's the sky's part R_sky I_dome + f_sun I_cs (`energyplus_sky`), the
    circumsolar sun diffuse to the glazing as it is to EnergyPlus's.

    Parameters as `incident_irradiance`'s (`sunlit` f_sun, `sky` R_sky: 1 unshaded; `sky_model`,
    `altitude`); angles (deg) and factors (-) the glazing's table, diffuse its factor for diffuse
    sun (-)."""
    direct, diffuse_sun = _transmitted_parts(position, ghi, dni, dhi, tilt, azimuth, albedo, angles, factors, diffuse,
                                             sunlit, sky, sky_model, altitude)
    sun = direct + diffuse_sun
    return np.where(np.isfinite(sun) & (sun > 0.0), sun, 0.0)


def transmitted_split(position, ghi, dni, dhi, tilt, azimuth, albedo, angles=(0.0, 90.0),
                      factors=(1.0, 1.0), diffuse=1.0, sunlit=1.0, sky=1.0, sky_model="isotropic", altitude=0.0):
    """(I_b, I_d) W/m2: `transmitted_irradiance`'s two terms apart, the direct
    f(theta) f_sun dni max(cos theta, 0) and the diffuse f_d [...], each 0 where not positive or not
    finite; the default table (f = 1 up to 90 deg, f_d = 1) is a glazing's without one."""
    parts = _transmitted_parts(position, ghi, dni, dhi, tilt, azimuth, albedo, angles, factors, diffuse, sunlit, sky,
                               sky_model, altitude)
    return tuple(np.where(np.isfinite(p) & (p > 0.0), p, 0.0) for p in parts)


def _transmitted_parts(position, ghi, dni, dhi, tilt, azimuth, albedo, angles, factors, diffuse, sunlit, sky,
                       sky_model, altitude):
    """(direct, diffuse) W/m2 of `transmitted_irradiance`, unclipped."""
    direct, dome, circumsolar, ground = _sky_parts(position, ghi, dni, dhi, tilt, azimuth, albedo, sky_model,
                                                   altitude)
    zenith = np.asarray(position["apparent_zenith"], dtype=float)
    theta = pvlib.irradiance.aoi(tilt, azimuth, zenith, np.asarray(position["azimuth"], dtype=float))
    f = np.interp(np.asarray(theta, dtype=float), list(angles) + [90.0 + 1e-9], list(factors) + [0.0], right=0.0)
    diffuse_sun = dome * sky + ground
    if circumsolar is not None:
        diffuse_sun = diffuse_sun + circumsolar * sunlit
    return f * direct * sunlit, diffuse * diffuse_sun
