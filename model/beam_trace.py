"""The direct sun a window lets in, traced onto the faces of its zone as EnergyPlus's
FullInteriorAndExterior distribution traces it (SolarShading.cc, CalcInteriorSolarDistribution);
where each share is then absorbed, `model.interior_sun`."""
import numpy as np
import shapely

from .geometry import outward_normal
from .shading import GRAZING, _robust, sun_vectors

# A face this far (m) beyond the window's plane along the sun's rays is behind it: a face in the
# window's own plane (its wall, a window beside it) gets none of its sun
BEHIND = 1e-6


def beam_shares(window, faces, sun):
    """Share of the direct sun a window lets in that falls on each inside face of its zone (-),
    as EnergyPlus's FullInteriorAndExterior distribution traces it (SolarShading.cc, the back
    surfaces of CalcInteriorSolarDistribution): the window's polygon projected along the sun's
    rays onto each face's plane and clipped by the face, here both projected onto the plane
    normal to the rays, where a patch keeps the ratio of its area to the window's,

        s_f = area(P(W) ∩ P(F_f)) / area(P(W)),   P the projection onto the plane normal to s,

    a face's holes (its windows, faces of their own) cut out of it. A face counts only behind the
    window, beyond its plane along the rays (its own wall and a window beside it get none); the
    zone is taken convex, as EnergyPlus takes it, no face hiding another from the window, and in
    one that is not the shares are scaled to add up to at most 1.

    Parameters
    ----------
    window : (m, 3) array_like
        The window's polygon, m (x east, y north, z up), counterclockwise seen from outside.
    faces : sequence of (vertices (k, 3), holes (sequence of (h, 3)))
        The zone's other inside faces, m.
    sun : (T, 3) array_like
        Unit vectors toward the sun; 0 where it is down.

    Returns
    -------
    numpy.ndarray (T, len(faces))
        s_f at each time, 0 where the sun is down or behind the window; 1 - their sum falls on no
        face."""
    s = np.atleast_2d(np.asarray(sun, dtype=float))
    window = np.asarray(window, dtype=float)
    normal = outward_normal(window)
    shares = np.zeros((len(s), len(faces)))
    lit = np.flatnonzero(s @ normal > GRAZING)
    if not len(lit):
        return shares
    s = s[lit]
    # (T, 2, 3): each ray's plane's axes (u, v), as `model.shading.plane_axes` makes them
    helper = np.where(np.abs(s[:, 2:]) < 0.9, [0.0, 0.0, 1.0], [1.0, 0.0, 0.0])
    u = np.cross(helper, s)
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    axes = np.stack([u, np.cross(s, u)], axis=1)

    def projected(polygon):
        return shapely.make_valid(shapely.polygons(np.einsum("mk,tjk->tmj", np.asarray(polygon, dtype=float), axes)))

    def along(points, polygon):
        """How far (m) the plane of `polygon` lies along s from the points (T, 2) of each ray's plane."""
        p = np.asarray(polygon, dtype=float)
        n = outward_normal(p)
        at = np.einsum("tj,tjk->tk", points, axes)
        with np.errstate(divide="ignore", invalid="ignore"):
            return ((p[0] - at) @ n) / (s @ n)

    light = projected(window)
    total = shapely.area(light)
    for k, (vertices, holes) in enumerate(faces):
        patch = _robust(shapely.intersection, light, projected(vertices))
        area = shapely.area(patch)
        for hole in holes:
            area = area - shapely.area(_robust(shapely.intersection, light, projected(hole)))
        coordinates, which = shapely.get_coordinates(shapely.point_on_surface(patch), return_index=True)
        inside = np.full((len(patch), 2), np.nan)  # a point in each patch; NaN where there is none
        inside[which] = coordinates
        behind = along(inside, vertices) < along(inside, window) - BEHIND
        shares[lit, k] = np.where(behind & (area > 0), np.clip(area, 0.0, None) / total, 0.0)
    return shares / np.maximum(1.0, shares.sum(axis=1, keepdims=True))


def may_receive_beam(window, face, step=5.0):
    """Whether any sun above the horizon sends a window's direct sun onto a face of its zone
    (`beam_shares`), both plane polygons ((m, 3) m, the window counterclockwise seen from
    outside): the face reaches beyond the window's plane into the zone, and for some sun in front
    of the window (s . n_w > 0, s_z > 0; directions every `step` deg) the rays cross the face's
    plane away from the window (s . n_f < 0, n_f its normal pointing away from the window). A
    zone's ceiling over a wall's window, the walls facing as the window does and the faces in its
    plane never do: their shares are 0 at every time, and a converter need not trace them."""
    window, face = np.asarray(window, dtype=float), np.asarray(face, dtype=float)
    n_w = outward_normal(window)
    if not np.any((window[0] - face) @ n_w > BEHIND):
        return False
    n_f = outward_normal(face)
    if (face.mean(axis=0) - window.mean(axis=0)) @ n_f < 0:
        n_f = -n_f
    altitude, azimuth = np.meshgrid(np.arange(step / 2, 90.0, step), np.arange(0.0, 360.0, step))
    sun = sun_vectors(90.0 - altitude.ravel(), azimuth.ravel())
    return bool(np.any((sun @ n_w > GRAZING) & (sun @ n_f < -GRAZING)))
