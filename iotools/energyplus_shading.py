"""EnergyPlus's shading objects as the polygons EnergyPlus builds from them (SurfaceGeometry.cc:
MakeRectangularVertices for Shading:Site and Shading:Building, the relative rectangles of
GetSimpleShdSurfaceData for the overhangs and fins a window carries), and the faces each may shade
(docs/model.md section 4.2). Coordinates in m (x east, y north, z up), angles in degrees,
azimuth clockwise from north; pure functions on numpy arrays.
"""
import numpy as np

# A shading polygon shades a face only where it stands this far (m) in front of the face's plane:
# an overhang touching its wall, or a roof's edge on a wall's top, lies in the plane and casts nothing
IN_FRONT = 1e-6


def rectangle(corner, azimuth, tilt, length, height):
    """(4, 3) vertices of EnergyPlus's rectangle from its lower-left corner (m): the surface of that
    azimuth and tilt, `length` along its bottom edge and `height` up its slope, listed from the
    upper-left corner counterclockwise seen from its outside (MakeRectangularVertices)."""
    a, t = np.radians(azimuth), np.radians(tilt)
    x = np.array([0.0, 0.0, length, length])
    y = np.array([height, 0.0, 0.0, height])
    return np.asarray(corner, dtype=float) + np.column_stack([
        -x * np.cos(a) - y * np.cos(t) * np.sin(a), x * np.sin(a) - y * np.cos(t) * np.cos(a), y * np.sin(t)])


def axes(azimuth, tilt):
    """(u, w): the unit vectors of a face of that azimuth and tilt along its bottom edge, left to
    right seen from outside, and up its slope: the axes of EnergyPlus's rectangles."""
    a, t = np.radians(azimuth), np.radians(tilt)
    return (np.array([-np.cos(a), np.sin(a), 0.0]),
            np.array([-np.cos(t) * np.sin(a), -np.cos(t) * np.cos(a), np.sin(t)]))


def on_surface(base, azimuth, tilt, x, z, length, height):
    """(4, 3) vertices of a rectangular window or door (EnergyPlus's Window, Door, GlazedDoor)
    `x` along and `z` up (m) from its base surface's second vertex (the lower-left corner of a
    surface listed counterclockwise from its upper-left one), `length` by `height` (m), in the
    base's plane (MakeRelativeRectangularVertices)."""
    u, w = axes(azimuth, tilt)
    return rectangle(np.asarray(base, dtype=float)[1] + x * u + z * w, azimuth, tilt, length, height)


def window_frame(vertices, azimuth, tilt):
    """(lower-left corner (3,), width, height, u, w) of a rectangular window of a face of that
    azimuth and tilt (`axes` u and w), width and height its extents along them (m)."""
    u, w = axes(azimuth, tilt)
    p = np.asarray(vertices, dtype=float)
    along, up = (p - p[0]) @ u, (p - p[0]) @ w
    return p[0] + along.min() * u + up.min() * w, np.ptp(along), np.ptp(up), u, w


def overhang(window, azimuth, tilt, above, tilt_from_window, left, right, depth):
    """An overhang over a window (Shading:Overhang, and :Projection with depth = its fraction times
    the window's height): a rectangle `above` (m) over the window's head, from `left` (m) beyond
    its left edge to `right` beyond its right, `depth` (m) deep, turned `tilt_from_window` (deg,
    90 square to the window) from the window's plane."""
    corner, width, height, u, w = window_frame(window, azimuth, tilt)
    return rectangle(corner - left * u + (height + above) * w, azimuth, tilt + tilt_from_window,
                     left + width + right, depth)


def fin(window, azimuth, tilt, side, extension, above, below, tilt_from_window, depth):
    """A fin beside a window (Shading:Fin, and :Projection with depth = its fraction times the
    window's width): on the `side` ("left" or "right", seen from outside) `extension` (m) beyond
    the window's edge, from `below` (m) under its sill to `above` over its head, `depth` (m) deep,
    turned `tilt_from_window` (deg, 90 square to the window) from the window's plane."""
    corner, width, height, u, w = window_frame(window, azimuth, tilt)
    across = -extension if side == "left" else width + extension
    return rectangle(corner + across * u - below * w, azimuth - (180.0 - tilt_from_window), tilt, -depth,
                     above + below + height)


def may_shade(shade, face, normal):
    """Whether any part of a shading polygon stands in front of a face's plane (a vertex more
    than IN_FRONT m out along its outward normal): what stands behind casts no shadow on it."""
    distance = (np.asarray(shade, dtype=float) - np.asarray(face, dtype=float)[0]) @ np.asarray(normal, dtype=float)
    return bool(np.max(distance) > IN_FRONT)
