"""The site a run computes at: the building file's, or, on an EPW recorded elsewhere, the EPW's.

EnergyPlus run on an EPW takes the site from the file's LOCATION line and ignores the IDF's
Site:Location (WeatherManager.cc: "Weather file location will be used rather than entered (IDF)
Location object"). A run here does the same (`run_building`): where the weather is an EPW whose
site (`weather.attrs["site"]`, `iotools.hourly.epw_site`) differs from the building file's by more
than `LATITUDE_LONGITUDE` in latitude or longitude, by more than `ELEVATION` in elevation, or in
its standard time's offset from UTC, the building computes at the EPW's site: the sun (latitude,
longitude, altitude), the local clock of its schedules and daily gains (timezone) and its air's
density (the elevation's pressure). A weather CSV carries no site: the building file's stands.
"""
import pandas as pd

from .errors import InputError
from .network import air_density_at

LATITUDE_LONGITUDE = 0.01  # deg: an EPW's LOCATION gives them to 0.01 deg
ELEVATION = 1.0  # m
# the fields of a building file's site that follow where its weather was recorded; the ground's
# albedo and temperature, the sky and the flows' density rule stay the file's, as EnergyPlus keeps
# the IDF's Site:GroundReflectance and Site:GroundTemperature objects
MOVED = ("latitude", "longitude", "altitude", "timezone", "air_density")


def standard_offset(timezone, when, source):
    """The offset (h) from UTC of `timezone`'s standard time (its daylight saving left out) at the
    tz-aware `when`; InputError naming `source`'s site.timezone for a zone that is none."""
    try:
        local = pd.Timestamp(when).tz_convert(timezone)
    except Exception as e:  # pandas raises several kinds for an unknown zone
        raise InputError(source, "site.timezone", f"{timezone!r} is not a time zone ({e})") from None
    return (local.utcoffset() - (local.dst() or pd.Timedelta(0))).total_seconds() / 3600.0


def differences(site, recorded, when, source):
    """The names of what the building file's `site` (of the file `source`) has otherwise than the
    `recorded` site (`iotools.hourly.epw_site`): "latitude", "longitude" (beyond
    `LATITUDE_LONGITUDE` deg), "altitude" (beyond `ELEVATION` m), "time zone" (another standard
    time at `when`)."""
    out = [name for name, tolerance in (("latitude", LATITUDE_LONGITUDE), ("longitude", LATITUDE_LONGITUDE),
                                        ("altitude", ELEVATION))
           if abs(site[name] - recorded[name]) > tolerance]
    if standard_offset(site["timezone"], when, source) != recorded["utc_offset"]:
        out.append("time zone")
    return out


def moved_site(site, recorded, when, source):
    """The building file's parsed `site` moved to the `recorded` one: its latitude, longitude (deg)
    and altitude (m); its timezone, unless the file's keeps the same standard time (its daylight
    saving rules then kept); and its air_density (kg/m3) rho p(z_recorded) / p(z_site), the ideal
    gas's density at one temperature following the pressure, p(z) the standard atmosphere's at
    elevation z (`network.air_density_at`), as EnergyPlus takes its barometric pressure from the
    weather file's elevation."""
    same_clock = standard_offset(site["timezone"], when, source) == recorded["utc_offset"]
    return {**site, "latitude": recorded["latitude"], "longitude": recorded["longitude"],
            "altitude": recorded["altitude"], "timezone": site["timezone"] if same_clock else recorded["timezone"],
            "air_density": site["air_density"] * air_density_at(recorded["altitude"]) / air_density_at(site["altitude"])}


def at_site(building, site):
    """`building` computing at `site` (a parsed site, of which its `MOVED` fields are taken): the
    same Building where they are already its own, else its file edited (`Building.edited`)."""
    if all(building.site[name] == site[name] for name in MOVED):
        return building
    return building.edited(lambda data: data["site"].update({name: site[name] for name in MOVED}))


def run_building(building, weather):
    """(the Building a run of `building` under `weather` computes, the assumption that says so):
    `building` itself and None, unless the weather is an EPW recorded at another site
    (`differences`): then `building` at the EPW's site (`moved_site`) and the sentence naming
    both sites, for the case's assumptions."""
    recorded = weather.attrs.get("site")
    if recorded is None or not len(weather.index):
        return building, None
    when, source = weather.index[0], building.source
    differ = differences(building.site, recorded, when, source)
    if not differ:
        return building, None
    site = moved_site(building.site, recorded, when, source)
    differ = ", ".join(differ[:-1]) + " and " + differ[-1] if len(differ) > 1 else differ[0]
    said = (f"The weather file's site ({recorded['name']}, {weather.attrs.get('source', 'weather')}: "
            f"{described(recorded, recorded['utc_offset'])}) is used, not the building file's ({source}: "
            f"{described(building.site, standard_offset(building.site['timezone'], when, source))}), whose "
            f"{differ} differ, as EnergyPlus uses an EPW's LOCATION over the IDF's Site:Location: the "
            f"sun, the local clock and the air's density ({site['air_density']:.4g} kg/m3, not "
            f"{building.site['air_density']:.4g}) follow it; the building files written back keep "
            "the building file's site.")
    return at_site(building, site), said


def described(site, offset):
    """"latitude 41.98, longitude -87.92 deg, UTC-6 h, 201 m" of a site and its UTC offset (h)."""
    return (f"latitude {site['latitude']:.2f}, longitude {site['longitude']:.2f} deg, UTC{offset:+g} h, "
            f"{site['altitude']:g} m")
