"""Shading surfaces on a building's faces: the sunlit fraction of a face at each sun position and
the share of the isotropic sky a face still sees (docs/model.md section 4.2).

EnergyPlus's shadow calculation (its Engineering Reference, "Shading Module"; SolarShading.cc's
SHADOW and SHDGSS) projects each shading polygon along the sun's rays onto the plane of the
receiving face, clips it to the face and sums the sunlit area; the diffuse ratio integrates the
same calculation over sky patches (SkyDifSolarShading). Here the projection is numpy's on all sun
positions at once and the clipping and union are shapely's (GEOS). Coordinates in m, +x east,
+y north, +z up; a sun direction is the unit vector from the face toward the sun.
"""
import numpy as np
import shapely

#: EnergyPlus's sky patches (SkyDifSolarShading): 6 altitudes of 15 deg centred at 7.5 .. 82.5 deg,
#: 24 azimuths every 15 deg from 0
SKY_ALTITUDES, SKY_AZIMUTHS = 6, 24

# A sun this close to the face's plane (cosine of its incidence) lights it no more: its shadows'
# projections grow as 1 / cos, and EnergyPlus's SUNCOS test keeps a positive cosine only
GRAZING = 1e-6


# The grid (m) a shadow is clipped and united on where GEOS's overlay in floating point fails on
# nearly coincident edges ("TopologyException: Ring edge missing", seen on EnergyPlus's
# SingleFamilyHouse_HP_Slab): snapped to a tenth of a millimetre it is robust, and an area moves
# by less than the edges' length times 1e-4 m
GRID = 1e-4


def _robust(operation, *args, **kwargs):
    """shapely's `operation` in floating point, or on the GRID where GEOS's overlay fails there."""
    try:
        return operation(*args, **kwargs)
    except shapely.errors.GEOSException:
        return operation(*args, grid_size=GRID, **kwargs)


def sun_vectors(zenith, azimuth):
    """(n, 3) unit vectors toward the sun from its zenith and azimuth (deg, azimuth clockwise
    from north), x east, y north, z up."""
    z, a = np.radians(np.asarray(zenith, dtype=float)), np.radians(np.asarray(azimuth, dtype=float))
    return np.column_stack([np.sin(z) * np.sin(a), np.sin(z) * np.cos(a), np.cos(z)])


def plane_axes(normal):
    """Two unit vectors (u, v) that with the unit normal n make a right-handed frame (u, v, n):
    the face's own 2-D axes."""
    n = np.asarray(normal, dtype=float)
    helper = np.array([0.0, 0.0, 1.0]) if abs(n[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    u = np.cross(helper, n)
    u /= np.linalg.norm(u)
    return u, np.cross(n, u)


def in_front(polygon, origin, normal):
    """The part of a plane polygon ((m, 3), m) on the outward side of the plane through `origin`
    with unit normal `normal` (distance >= 0), by one Sutherland-Hodgman pass: only what stands
    in front of a face can shade it (EnergyPlus clips a casting surface at the receiving plane)."""
    p = np.asarray(polygon, dtype=float)
    d = (p - origin) @ normal
    out = []
    for k in range(len(p)):
        j = (k + 1) % len(p)
        if d[k] >= 0:
            out.append(p[k])
        if (d[k] >= 0) != (d[j] >= 0):
            out.append(p[k] + (p[j] - p[k]) * d[k] / (d[k] - d[j]))
    return np.array(out).reshape(-1, 3)


def face_polygon(vertices, normal, holes=()):
    """The face as a shapely polygon in its own axes (`plane_axes`, origin its first vertex),
    with its holes (its windows, which are faces of their own)."""
    origin = np.asarray(vertices, dtype=float)[0]
    u, v = plane_axes(normal)
    flat = lambda p: (np.asarray(p, dtype=float) - origin) @ np.column_stack([u, v])  # noqa: E731
    return shapely.Polygon(flat(vertices), [flat(h) for h in holes])


def sunlit_fraction(vertices, normal, shades, sun, holes=()):
    """The sunlit fraction of a plane face at each sun position (-).

    Parameters
    ----------
    vertices : (n, 3) array_like
        The face's polygon, m.
    normal : (3,) array_like
        Its unit outward normal.
    shades : sequence of (m, 3) array_like
        The shading polygons, m (either side casts a shadow).
    sun : (T, 3) array_like
        Unit vectors toward the sun.
    holes : sequence of (k, 3) array_like
        Polygons cut out of the face (its windows), m.

    Returns
    -------
    numpy.ndarray (T,)
        1 - A_shadow / A, A_shadow the area of the union of the shades' shadows on the face, each
        shade (its part in front of the face) projected along the sun onto the face's plane,
        P' = P - s ((P - O) . n) / (s . n); 0 where the sun is behind the face (s . n <= 0).
    """
    n = np.asarray(normal, dtype=float)
    s = np.atleast_2d(np.asarray(sun, dtype=float))
    origin = np.asarray(vertices, dtype=float)[0]
    face = shapely.make_valid(face_polygon(vertices, n, holes))
    cos = s @ n
    lit = cos > GRAZING
    fraction = np.zeros(len(s))
    fraction[lit] = 1.0
    front = [p for p in (in_front(shade, origin, n) for shade in shades) if len(p) >= 3]
    if not front or not lit.any():
        return fraction
    s, cos = s[lit], cos[lit]
    axes = np.column_stack(plane_axes(n))
    low, high = np.array(face.bounds[:2]), np.array(face.bounds[2:])
    shadows = np.full((len(front), len(s)), None, dtype=object)
    for k, p in enumerate(front):
        depth = (p - origin) @ n  # (m,), m in front of the plane
        projected = p[None, :, :] - s[:, None, :] * (depth[None, :] / cos[:, None])[:, :, None]
        rings = (projected - origin) @ axes  # (T, m, 2) in the face's axes
        # GEOS only where the shadow's bounding box meets the face's: most of a building's
        # surfaces shade a face at few hours
        meets = np.all((rings.min(axis=1) < high) & (rings.max(axis=1) > low), axis=1)
        shadows[k, meets] = _robust(shapely.intersection, shapely.make_valid(shapely.polygons(rings[meets])), face)
    hit = np.flatnonzero((shadows != None).any(axis=0))  # noqa: E711 (elementwise on objects)
    shaded = np.zeros(len(s))
    shaded[hit] = shapely.area(_robust(shapely.union_all, shadows[:, hit], axis=0))
    fraction[lit] = 1.0 - shaded / face.area
    return np.clip(fraction, 0.0, 1.0)


def sky_patches(altitudes=SKY_ALTITUDES, azimuths=SKY_AZIMUTHS):
    """(unit vectors (k, 3) toward the centres of the sky patches, their weights cos(phi) (-)):
    altitude phi in equal steps centred in (0, 90 deg), azimuth in equal steps from 0, as
    EnergyPlus's SkyDifSolarShading lays them; a patch's solid angle is cos(phi) dphi dtheta, and
    the steps are equal, so cos(phi) weighs it."""
    phi = (np.arange(altitudes) + 0.5) * (np.pi / 2) / altitudes
    theta = np.arange(azimuths) * 2 * np.pi / azimuths
    phi, theta = np.meshgrid(phi, theta, indexing="ij")
    phi, theta = phi.ravel(), theta.ravel()
    vectors = np.column_stack([np.cos(phi) * np.cos(theta), np.cos(phi) * np.sin(theta), np.sin(phi)])
    return vectors, np.cos(phi)


def sky_diffuse_ratio(vertices, normal, shades, holes=(), altitudes=SKY_ALTITUDES, azimuths=SKY_AZIMUTHS):
    """The share of an isotropic sky's diffuse irradiance a face gets with its shades (-),
    EnergyPlus's DifShdgRatioIsoSky:

        R = sum_k cos(phi_k) cos(theta_k) f_k / sum_k cos(phi_k) cos(theta_k)

    over the sky patches k (`sky_patches`) in front of the face (cos theta_k > 0, theta_k the
    incidence of the patch's centre), f_k the face's sunlit fraction for a sun at the patch's
    centre (`sunlit_fraction`). Parameters as `sunlit_fraction`'s; altitudes and azimuths the
    patches' counts (EnergyPlus's 6 and 24 by default)."""
    directions, weights = sky_patches(altitudes, azimuths)
    cos = directions @ np.asarray(normal, dtype=float)
    seen = cos > 0
    if not seen.any():  # a face looking straight down sees no patch: nothing of the sky to shade
        return 1.0
    w = weights[seen] * cos[seen]
    f = sunlit_fraction(vertices, normal, shades, directions[seen], holes)
    return float(np.sum(w * f) / np.sum(w))
