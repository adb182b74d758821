"""Write a synthetic office building, its weather and its sensors: the full-size case of issue 20.

The building is generated, not measured: `storeys` storeys of a double-loaded plan, each with
`offices` offices on the north side and as many on the south, a corridor between them running
east-west and a stairwell at the east end. Components: exterior walls and a window on every
facade of every zone that has one, partitions (office to office, office to corridor with a door,
corridor and the end offices to the stairs), floors between storeys (one component, the upper
zone's floor and the lower zone's ceiling), a ground floor on a constant ground temperature and
a roof. Each office has supply air, passes it on to the corridor, which passes it to the
stairwell, where it is extracted; each office has a heater whose measured power is the column
`heater` (office hours, 30 % radiative). The weather is the bundled Miami typical year
(`model/data/miami_tmy2.csv`) with the `heater` column added.

Sensors: every zone's air and, per office, the inside surface of its exterior wall, the layer
boundary behind the wall's concrete and the inside surface of its floor; per corridor and
stairwell, the floor and the partition to the next office. `--small` gives two storeys of two
offices a side and only the exterior wall's two sensors per office (the tests' case).

    python examples/office/make_building.py OUT_DIR [--small]

writes OUT_DIR/building.json, OUT_DIR/weather.csv and OUT_DIR/sensors.txt (the measured node
ids, for `nodeforce synth --sensors`).
"""
import argparse
import json
from pathlib import Path

import numpy as np
import pandas as pd

REPO = Path(__file__).resolve().parents[2]
WEATHER = REPO / "model" / "data" / "miami_tmy2.csv"
SITE = {"latitude": 25.8, "longitude": -80.26666666666667, "altitude": 2.0, "timezone": "Etc/GMT+5",
        "ground_albedo": 0.2}

# --- Geometry, m -----------------------------------------------------------------------------
BAY = 4.0  # office width along the facade
OFFICE_DEPTH = 5.0
CORRIDOR_WIDTH = 2.0
STAIR_WIDTH = 4.0  # along the facade; the stairwell spans the whole depth of the plan
HEIGHT = 3.0  # storey height
WINDOW_AREA = 3.6  # m2 per facade of a zone (offices 30 % of the facade)
DOOR_AREA = 1.9

# --- Surfaces, W/m2/K (EN ISO 6946 as in the Twin House) ---------------------------------------
H_RAD_IN, H_RAD_OUT, H_CONV_OUT = 5.1, 4.6, 14.6
H_CONV_WALL, H_CONV_UP, H_CONV_DOWN = 2.5, 5.0, 0.7

MATERIALS = {  # conductivity W/m/K, density kg/m3, specific heat J/kg/K
    "plaster": (0.7, 1400.0, 1000.0),
    "concrete": (2.0, 2400.0, 900.0),
    "mineral_wool": (0.036, 60.0, 840.0),
    "render": (0.8, 1500.0, 1000.0),
    "brick": (0.5, 1200.0, 1000.0),
    "screed": (1.4, 2000.0, 1000.0),
    "eps": (0.035, 25.0, 1400.0),
    "wood": (0.13, 600.0, 1600.0),
    "glazing_equivalent": (0.012, 2500.0, 750.0),  # 8 mm: U about 1.1 W/m2/K between the surfaces
}
# Layers from the inside face outwards (m)
EXTERIOR_WALL = [("plaster", 0.015), ("concrete", 0.2), ("mineral_wool", 0.12), ("render", 0.01)]
WALL_CONCRETE_END = 0.215  # the sensor behind the concrete, m from the inside face
PARTITION = [("plaster", 0.01), ("brick", 0.115), ("plaster", 0.01)]
SLAB = [("screed", 0.05), ("eps", 0.03), ("concrete", 0.22)]  # from the upper (floor) face down
GROUND_FLOOR = [("screed", 0.05), ("eps", 0.08), ("concrete", 0.25)]
ROOF = [("plaster", 0.01), ("concrete", 0.22), ("eps", 0.2), ("render", 0.01)]
DOOR = [("wood", 0.04)]
GLAZING = [("glazing_equivalent", 0.008)]
T_GROUND = 22.0  # C, under the ground floor (Miami)
NODES = {"wall": {"max_spacing": 0.04}, "partition": {"max_spacing": 0.03, "layer_boundaries": False},
         "slab": {"max_spacing": 0.05}, "thin": {"max_spacing": 1.0}}

# --- Air and heat --------------------------------------------------------------------------------
SUPPLY_FLOW = 60.0  # m3/h per office
SUPPLY_TEMPERATURE = 20.0  # C
AIR_CHANGE_RATE = 0.2  # 1/h, infiltration of every zone
HEATER = "heater"  # W per office, the column added to the weather
HEATER_POWER = 400.0  # W, office hours 7-18 local time on weekdays
HEATER_RADIATIVE_FRACTION = 0.3
TRANSMITTANCE = 0.5
ABSORPTANCE = 0.4


def _surface(zone, h_conv):
    return {"zone": zone, "h_conv": h_conv, "h_rad": H_RAD_IN}


def _exterior(absorptance=ABSORPTANCE):
    return {"type": "exterior", "h_conv": H_CONV_OUT, "h_rad": H_RAD_OUT, "solar_absorptance": absorptance}


def _component(name, area, tilt, azimuth, layers, nodes, inside, outside, **extra):
    return {"name": name, "area": round(area, 4), "tilt": tilt, "azimuth": azimuth,
            "layers": [list(layer) for layer in layers], "nodes": NODES[nodes],
            "inside": inside, "outside": outside, **extra}


def office(storey, side, i):
    return f"s{storey}_{side}{i}"


def plan(offices):
    """The zones of one storey's plan and their facades: {zone suffix: (volume m3, facades)},
    a facade (azimuth, width m)."""
    zones = {}
    for i in range(offices):
        for side, azimuth in (("N", 0.0), ("S", 180.0)):
            facades = [(azimuth, BAY)] + ([(270.0, OFFICE_DEPTH)] if i == 0 else [])
            zones[f"{side}{i}"] = (BAY * OFFICE_DEPTH * HEIGHT, facades)
    zones["corridor"] = (offices * BAY * CORRIDOR_WIDTH * HEIGHT, [(270.0, CORRIDOR_WIDTH)])
    depth = 2 * OFFICE_DEPTH + CORRIDOR_WIDTH
    zones["stairs"] = (STAIR_WIDTH * depth * HEIGHT, [(90.0, depth), (0.0, STAIR_WIDTH), (180.0, STAIR_WIDTH)])
    return zones


def building(storeys, offices, sensors_per_office=3):
    """The building file's data and the sensors' names in the order of sensors.txt."""
    zones, components, sensors = [], [], {}
    rooms = plan(offices)
    footprint = {name: (BAY * OFFICE_DEPTH if name[0] in "NS" else
                        offices * BAY * CORRIDOR_WIDTH if name == "corridor" else
                        STAIR_WIDTH * (2 * OFFICE_DEPTH + CORRIDOR_WIDTH)) for name in rooms}
    for s in range(storeys):
        def z(name):
            return f"s{s}_{name}"
        for name, (volume, facades) in rooms.items():
            zone = {"name": z(name), "volume": volume, "air_change_rate": AIR_CHANGE_RATE}
            if name[0] in "NS":
                zone.update(heat_input=HEATER, heat_input_radiative_fraction=HEATER_RADIATIVE_FRACTION,
                            supply={"flow": SUPPLY_FLOW, "temperature": SUPPLY_TEMPERATURE})
            elif name == "corridor":
                zone["airflow_from"] = [{"zone": z(o), "flow": SUPPLY_FLOW} for o in rooms if o[0] in "NS"]
            else:
                zone["airflow_from"] = [{"zone": z("corridor"), "flow": 2 * offices * SUPPLY_FLOW}]
            zones.append(zone)
            for azimuth, width in facades:
                side = {0.0: "N", 90.0: "E", 180.0: "S", 270.0: "W"}[azimuth]
                wall, window = f"{z(name)}_wall{side}", f"{z(name)}_win{side}"
                components.append(_component(wall, width * HEIGHT - WINDOW_AREA, 90.0, azimuth, EXTERIOR_WALL,
                                             "wall", _surface(z(name), H_CONV_WALL), _exterior()))
                components.append(_component(window, WINDOW_AREA, 90.0, azimuth, GLAZING, "thin",
                                             _surface(z(name), H_CONV_WALL), _exterior(0.1),
                                             solar_transmittance=TRANSMITTANCE,
                                             transmitted_solar_to=f"{z(name)}_floor"))
            # the floor: on the ground, or over the same zone of the storey below
            if s == 0:
                outside = {"type": "boundary", "temperature": T_GROUND, "h": 1.0 / 0.17}
                layers = GROUND_FLOOR
            else:
                outside = {"type": "zone", **_surface(f"s{s - 1}_{name}", H_CONV_UP)}
                layers = SLAB
            components.append(_component(f"{z(name)}_floor", footprint[name], 180.0, 0.0, layers, "slab",
                                         _surface(z(name), H_CONV_DOWN), outside))
            if s == storeys - 1:
                components.append(_component(f"{z(name)}_roof", footprint[name], 0.0, 0.0, ROOF, "slab",
                                             _surface(z(name), H_CONV_UP), _exterior(0.6)))
        # partitions of the storey: office to office, office to corridor (and its door), to the stairs
        for side in "NS":
            for i in range(offices):
                here = z(f"{side}{i}")
                if i + 1 < offices:
                    components.append(_component(f"{here}_part", OFFICE_DEPTH * HEIGHT, 90.0, 90.0, PARTITION,
                                                 "partition", _surface(here, H_CONV_WALL),
                                                 {"type": "zone", **_surface(z(f"{side}{i + 1}"), H_CONV_WALL)}))
                else:
                    components.append(_component(f"{here}_stairs", OFFICE_DEPTH * HEIGHT, 90.0, 90.0, PARTITION,
                                                 "partition", _surface(here, H_CONV_WALL),
                                                 {"type": "zone", **_surface(z("stairs"), H_CONV_WALL)}))
                components.append(_component(f"{here}_corr", BAY * HEIGHT - DOOR_AREA, 90.0, 0.0, PARTITION,
                                             "partition", _surface(here, H_CONV_WALL),
                                             {"type": "zone", **_surface(z("corridor"), H_CONV_WALL)}))
                components.append(_component(f"{here}_door", DOOR_AREA, 90.0, 0.0, DOOR, "thin",
                                             _surface(here, H_CONV_WALL),
                                             {"type": "zone", **_surface(z("corridor"), H_CONV_WALL)}))
        components.append(_component(f"{z('corridor')}_stairs", CORRIDOR_WIDTH * HEIGHT, 90.0, 90.0, PARTITION,
                                     "partition", _surface(z("corridor"), H_CONV_WALL),
                                     {"type": "zone", **_surface(z("stairs"), H_CONV_WALL)}))
        # sensors: every zone's air; per office its exterior wall (inside face, behind the
        # concrete) and its floor; the corridor's and the stairwell's floor and a partition
        for name in rooms:
            sensors[f"{z(name)}_air"] = {"zone": z(name)}
        for name in rooms:
            if name[0] in "NS":
                wall = f"{z(name)}_wall{name[0]}"
                chosen = [(f"{wall}_in", wall, 0.0), (f"{wall}_mid", wall, WALL_CONCRETE_END),
                          (f"{z(name)}_floor_in", f"{z(name)}_floor", 0.0)][:sensors_per_office]
            else:
                partition = f"{z('corridor')}_stairs"
                chosen = [(f"{z(name)}_floor_in", f"{z(name)}_floor", 0.0),
                          (f"{partition}_{'in' if name == 'corridor' else 'out'}", partition,
                           0.0 if name == "corridor" else round(sum(t for _, t in PARTITION), 6))]
            for sensor, component, depth in chosen:
                sensors[sensor] = {"component": component, "depth": depth}
    data = {
        "format": "nodal-building/1",
        "name": f"Synthetic office, {storeys} storeys of {2 * offices} offices",
        "description": ("Generated by examples/office/make_building.py: a double-loaded office plan with a "
                        "corridor and a stairwell per storey, supply air, heaters, windows on every facade."),
        "site": SITE,
        "materials": {name: {"conductivity": k, "density": rho, "specific_heat": c}
                      for name, (k, rho, c) in MATERIALS.items()},
        "zones": zones,
        "components": components,
        "sensors": sensors,
    }
    return data


def weather(source=WEATHER):
    """The bundled typical year with the offices' heater power (W) added: HEATER_POWER on
    weekdays from 7 to 18 h local time, else 0."""
    frame = pd.read_csv(source)
    local = pd.to_datetime(frame["time"], utc=True).dt.tz_convert(SITE["timezone"])
    on = (local.dt.hour >= 7) & (local.dt.hour < 18) & (local.dt.day_of_week < 5)
    frame[HEATER] = np.where(on, HEATER_POWER, 0.0)
    return frame


def write(out, storeys, offices, sensors_per_office):
    """Write building.json, weather.csv and sensors.txt in `out`; return the building file's path."""
    from nodeforce.model.building_file import load_building
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    path = out / "building.json"
    path.write_text(json.dumps(building(storeys, offices, sensors_per_office), indent=1) + "\n")
    weather().to_csv(out / "weather.csv", index=False)
    loaded = load_building(path)
    (out / "sensors.txt").write_text(",".join(str(i) for i in loaded.sensors.values()) + "\n")
    return path


FULL = {"storeys": 4, "offices": 4, "sensors_per_office": 2}
SMALL = {"storeys": 2, "offices": 2, "sensors_per_office": 1}

if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", help="folder for building.json, weather.csv and sensors.txt")
    parser.add_argument("--small", action="store_true", help="two storeys of four offices (the tests' case)")
    args = parser.parse_args()
    path = write(args.out, **(SMALL if args.small else FULL))
    print(f"wrote {path}")
