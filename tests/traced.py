"""The test cell whose window traces its direct sun (docs/model.md section 4.1): the cell's
3 x 3 x 2.5 m box, its 1 x 0.8 m south window 0.6 m above the floor."""
import copy

# counterclockwise seen from outside, x east, y north, z up (m)
POLYGONS = {
    "window": [(1, 0, 0.6), (2, 0, 0.6), (2, 0, 1.4), (1, 0, 1.4)],
    "floor": [(0, 0, 0), (0, 3, 0), (3, 3, 0), (3, 0, 0)],
    "north_wall": [(3, 3, 0), (0, 3, 0), (0, 3, 2.5), (3, 3, 2.5)],
    "east_wall": [(3, 0, 0), (3, 3, 0), (3, 3, 2.5), (3, 0, 2.5)],
    "west_wall": [(0, 3, 0), (0, 0, 0), (0, 0, 2.5), (0, 3, 2.5)],
}


def traced_cell(data, splits=None, residual=None):
    """The cell's data with its window's direct sun traced onto the floor and the north, east and
    west walls, each face absorbing 0.6 of what falls on it (or `splits[face]`), what falls on
    none split by `residual` (default the floor's 0.5)."""
    data = copy.deepcopy(data)
    components = {c["name"]: c for c in data["components"]}
    for name, polygon in POLYGONS.items():
        components[name]["vertices"] = [list(p) for p in polygon]
    window = components["window"]
    window["solar_distribution"] = residual or {"floor": 0.5}
    window["diffuse_distribution"] = {"floor": 0.3, "roof": 0.3, "north_wall": 0.2}
    window["traced_beam"] = {face: (splits or {}).get(face, {face: 0.6}) for face in POLYGONS if face != "window"}
    return data
