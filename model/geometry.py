"""Plane polygons of a building's surfaces: area, outward normal, azimuth and tilt, and the volume
they enclose (docs/model.md section 1.1). Coordinates in m, angles in degrees; azimuth clockwise
from north (+y is north, +x east, +z up), tilt from horizontal (0 faces up, 180 faces down).
"""
import numpy as np


def newell_normal(vertices):
    """Newell's vector of a plane polygon (m2): its direction is the normal that sees the vertices
    counterclockwise, its length the polygon's area. `vertices` (n, 3) in m, n >= 3."""
    p = np.asarray(vertices, dtype=float)
    q = np.roll(p, -1, axis=0)
    return 0.5 * np.array([np.sum((p[:, 1] - q[:, 1]) * (p[:, 2] + q[:, 2])),
                           np.sum((p[:, 2] - q[:, 2]) * (p[:, 0] + q[:, 0])),
                           np.sum((p[:, 0] - q[:, 0]) * (p[:, 1] + q[:, 1]))])


def area(vertices):
    """Area of a plane polygon (m2)."""
    return float(np.linalg.norm(newell_normal(vertices)))


def outward_normal(vertices, counterclockwise=True):
    """Unit outward normal of a polygon whose vertices are listed counterclockwise seen from
    outside (`counterclockwise=False`: clockwise, EnergyPlus's GlobalGeometryRules)."""
    n = newell_normal(vertices)
    n = n / np.linalg.norm(n)
    return n if counterclockwise else -n


def azimuth_tilt(normal):
    """(azimuth, tilt) in degrees of a unit outward normal: azimuth clockwise from north (+y),
    in [0, 360); tilt the angle of the normal from the vertical, 0 facing up, 90 a wall."""
    nx, ny, nz = normal
    tilt = float(np.degrees(np.arccos(np.clip(nz, -1.0, 1.0))))
    horizontal = np.hypot(nx, ny)
    azimuth = 0.0 if horizontal < 1e-9 else float(np.degrees(np.arctan2(nx, ny))) % 360.0
    return azimuth, tilt


def turned_from(normal, tilt, azimuth):
    """How far (deg) a unit outward normal turns from a declared tilt and azimuth (deg): the larger
    of the tilts' difference and the azimuths' (none on a horizontal face)."""
    own_azimuth, own_tilt = azimuth_tilt(normal)
    turn = abs((own_azimuth - azimuth + 180) % 360 - 180) if 1e-6 < own_tilt < 180 - 1e-6 else 0.0
    return max(abs(own_tilt - tilt), turn)


def rotate_z(vertices, degrees):
    """Vertices (n, 3) turned clockwise seen from above by `degrees` about the z axis: a zone or a
    building whose relative north is `degrees` east of true north."""
    a = np.radians(degrees)
    p = np.asarray(vertices, dtype=float)
    x, y = p[:, 0], p[:, 1]
    return np.column_stack([x * np.cos(a) + y * np.sin(a), -x * np.sin(a) + y * np.cos(a), p[:, 2]])


def enclosed_volume(polygons, counterclockwise=True):
    """Volume (m3) enclosed by closed plane polygons, each listed counterclockwise seen from
    outside (or all clockwise): by the divergence theorem, V = sum over faces of A (n . p) / 3,
    p any vertex of the face."""
    volume = 0.0
    for vertices in polygons:
        n = newell_normal(vertices) * (1.0 if counterclockwise else -1.0)
        volume += float(np.dot(n, np.asarray(vertices, dtype=float)[0])) / 3.0
    return volume
