"""Write building.json, the Twin House N2 ground floor, from the tables of BUILDING.md.

Every number below is BUILDING.md's (IDEAS values, IDEAS areas on external dimensions) or a
modelling assumption stated in README.md; this script is the one place they are written down, and
tests/test_twinhouse.py checks that building.json is its output. Run it from anywhere:

    python examples/twinhouse_n2/make_building.py

The same house under experiment 2's protocol (60 m3/h of supply air, the blinds of W27 and W33
closed: a shading column each), optionally with the effects a diagnosis added on experiment 1
(report.json's "effects"), is written by

    python examples/twinhouse_n2/make_building.py --experiment 2 -o FILE [--corrected-by REPORT]
"""
import argparse
import json
from pathlib import Path

from nodeforce.model import convection, glazing

HERE = Path(__file__).resolve().parent

# --- Surface coefficients, W/m2/K (README "Surface coefficients") --------------------------
EMISSIVITY = 0.9  # BUILDING.md: longwave emissivity 0.9
H_RAD_IN = 5.1  # EMISSIVITY x 4 sigma T^3 at 20 C (EN ISO 6946 h_r0 = 5.7)
H_RAD_OUT = 4.6  # EMISSIVITY x 4 sigma T^3 at 10 C (h_r0 = 5.1)
H_CONV_HORIZONTAL_FLOW = 2.5  # EN ISO 6946, walls and windows
H_CONV_UPWARD_FLOW = 5.0  # EN ISO 6946, both faces of the ceiling
H_CONV_DOWNWARD_FLOW = 0.7  # EN ISO 6946, both faces of the floor

# --- Coefficients that follow the state (README "Surface coefficients"; docs/model.md 3.6) --
# The rooms' air is stirred by nothing but the heaters' plumes and 120 m3/h of supply air: natural
# convection, which TARP follows face by face with the air-to-face temperature difference.
INSIDE_CONVECTION = "tarp"
# The weather mast measures the wind (m/s, deg from north), taken as EnergyPlus's station at 10 m
# in open country; the test site is an open field ("country"), and a ground-floor facade's centroid
# half a storey (3.28 m) above the floor, taken at grade.
TERRAIN = "country"
FACADE_CENTROID_HEIGHT = 1.64  # m
WIND_FACTOR = round(float(convection.wind_at_height(1.0, FACADE_CENTROID_HEIGHT, TERRAIN)), 6)
MEAN_WIND_SPEED = 2.65  # m/s, the record's mean: where the step matrix holds DOE-2's h
# DOE-2 roughness multipliers (EnergyPlus's Material Roughness): the thin render MediumRough, the
# wood door MediumSmooth, glass (and its PVC frame) 1, as EnergyPlus takes a window's outer face
ROUGHNESS_RENDER = convection.ROUGHNESS["mediumrough"]
ROUGHNESS_DOOR = convection.ROUGHNESS["mediumsmooth"]
ROUGHNESS_GLASS = 1.0

# --- Air flows (BUILDING.md "Ventilation", "Zones") ---------------------------------------
N50 = 1.62  # 1/h, N2
AIR_CHANGE_RATE = round(N50 / 20, 4)  # 1/h, the n50/20 rule of thumb, every zone alike

HEATER_RADIATIVE_FRACTION = 0.3
SOLAR_ABSORPTANCE_OUT = 0.23  # light plaster; also the white U-PVC frames and the entrance door

# --- Materials: IDEAS values, (conductivity W/m/K, density kg/m3, specific heat J/kg/K) ----
MATERIALS = {
    "ext_plaster": (0.8, 1200.0, 1000.0),
    "pu_insulation": (0.035, 80.0, 840.0),
    "former_ext_plaster": (1.0, 1200.0, 1000.0),
    "honeycomb_brick_ext": (0.22, 800.0, 1000.0),
    "int_plaster": (1.0, 1200.0, 1000.0),
    "eps": (0.04, 80.0, 840.0),
    "mineral_wool": (0.036, 80.0, 840.0),
    "screed": (1.4, 2000.0, 1000.0),
    "ceiling_insulation": (0.04, 80.0, 840.0),
    "concrete": (2.0, 2400.0, 840.0),
    "ceiling_plaster": (1.0, 1200.0, 840.0),
    "under_ceiling_insulation": (0.035, 80.0, 1000.0),
    "floor_concrete": (2.1, 2000.0, 1000.0),
    "levelling_fill": (0.06, 80.0, 840.0),
    "pur_board": (0.025, 80.0, 840.0),
    "composite_pur_panel": (0.023, 80.0, 840.0),
    "partition_plaster": (0.35, 1200.0, 1000.0),
    "honeycomb_brick_int": (0.331, 1000.0, 1000.0),
    "wood": (0.131, 600.0, 1000.0),
}

def _ext_wall(insulation, thickness):
    """Layers of an outer wall, inside face first, around its added insulation (m)."""
    return [("int_plaster", 0.01), ("honeycomb_brick_ext", 0.30), ("former_ext_plaster", 0.03),
            (insulation, thickness), ("ext_plaster", 0.01)]


# Constructions, layers from the INSIDE (room) face outwards: BUILDING.md's lists reversed.
CONSTRUCTIONS = {
    "extwall_S_N": _ext_wall("pu_insulation", 0.12),
    "extwall_E": _ext_wall("pu_insulation", 0.08),
    "extwall_Ws": _ext_wall("eps", 0.08),
    "extwall_Wn": _ext_wall("mineral_wool", 0.08),  # int plaster 0.01, not IDEAS' 0.10 typo
    "ceiling": [("under_ceiling_insulation", 0.10), ("ceiling_plaster", 0.01), ("concrete", 0.22),
                ("ceiling_insulation", 0.04), ("screed", 0.04)],
    "floor": [("screed", 0.065), ("composite_pur_panel", 0.033), ("pur_board", 0.03),
              ("levelling_fill", 0.029), ("floor_concrete", 0.22)],
    "intwall_1": [("partition_plaster", 0.01), ("honeycomb_brick_int", 0.24), ("partition_plaster", 0.01)],
    "intwall_2": [("partition_plaster", 0.01), ("honeycomb_brick_int", 0.115), ("partition_plaster", 0.01)],
    "door": [("wood", 0.04)],
    "column": [("concrete", 0.07)],
}

# Node generation (m): fine in the instrumented wall, a few cells in heavy layers elsewhere,
# two nodes (the paper's R2C) for thin single-layer components and the thin partitions.
NODES = {
    "W9": {"max_spacing": 0.05},
    "extwall": {"max_spacing": 0.1},
    "slab": {"max_spacing": 0.25},
    "intwall": {"max_spacing": 0.13, "layer_boundaries": False},
    "thin": {"max_spacing": 1.0},
}

# --- Glazing (BUILDING.md "Windows and doors") ---------------------------------------------
G_NORMAL, TAU_NORMAL, TAU_DIFFUSE = 0.525, 0.543, 0.427
GLASS = (1.0, 2500.0, 750.0)  # EN ISO 10456 glass, W/m/K, kg/m3, J/kg/K
# 4 mm clear float / 16 mm argon (90 %) / 4 mm low-e, outside first (m); the low-e coating of the
# inner pane faces the gap (IDEAS Glazing.mo: 0.04 there, 0.837 on every uncoated glass face)
PANE, GAP = 0.004, 0.016
GAP_GAS = [["argon", 0.9], ["air", 0.1]]
EMISSIVITY_GLASS, EMISSIVITY_LOW_E = 0.837, 0.04
# the gap's gas (argon-air) carries no capacity worth a node's: the air's, as the converter has it
GAS_DENSITY, GAS_SPECIFIC_HEAT = 1.2, 1005.0
# id: (zone, azimuth, area m2, frame fraction, opening width m, opening height m)
WINDOWS = {
    "W27": ("bedroom", 0.0, 2.1402, 0.397, 1.23, 1.54),
    "W28": ("bath", 90.0, 2.1402, 0.397, 1.23, 1.54),
    "W29": ("child", 180.0, 2.1402, 0.397, 1.23, 1.54),
    "W30": ("living", 180.0, 2.8527, 0.354, 1.11, 2.37),
    "W31": ("living", 180.0, 5.8116, 0.293, 3.34, 1.54),
    "W32": ("living", 270.0, 2.1402, 0.397, 1.23, 1.54),
    "W33": ("kitchen", 270.0, 2.1402, 0.397, 1.23, 1.54),
}
SOUTH_SHADING = "shading_south"  # 1 blinds open, 0 closed (N2 Exp1: 0 throughout)

# --- What differs between the experiments (the data's READMEs) ------------------------------
# supply_flow: m3/h into living, at vent_SUA_corr_AT; shaded: windows whose blinds differ from
# the others', each with its own shading column (1 open, 0 closed), besides the south windows'.
EXPERIMENTS = {1: {"supply_flow": 120.0, "shaded": {}},
               2: {"supply_flow": 60.0, "shaded": {"W27": "shading_W27", "W33": "shading_W33"}}}

# --- Zones: IDEAS volumes (m3) and measured heat inputs (columns without the N2_ prefix) -----
ZONES = {
    "living": (86.42, ["heat_elP_living_room"]),
    "corridor": (12.09, []),
    "bath": (15.44, ["heat_elP_bath_room"]),
    "child": (27.62, ["heat_elP_children_room"]),
    "kitchen": (18.56, ["heat_elP_kitchen", "HeatInputKitchen"]),
    "doorway": (14.65, ["heat_elP_doorway"]),
    "bedroom": (26.82, ["heat_elP_bedroom"]),
}
# Air leaves living for the corridor, which passes it on to bath and child (50/50), where it is
# extracted: (receiving zone, sending zone, m3/h).
def airflows(supply_flow):
    """(to, from, m3/h): the supply air on from living to the corridor, half of it to each of
    bath and child, where it is extracted."""
    return [("corridor", "living", supply_flow), ("bath", "corridor", supply_flow / 2),
            ("child", "corridor", supply_flow / 2)]

FACADE_IRRADIANCE = {0.0: "Solar_radiation_global_vertical_north",
                     90.0: "Solar_radiation_global_vertical_east",
                     180.0: "Solar_radiation_global_vertical_south",
                     270.0: "Solar_radiation_global_vertical_west"}
ATTIC, CELLAR = "attic_east_AT", "cellar_AT"

# --- Components of N2 (BUILDING.md "Components of N2 in IDEAS"), IDEAS areas m2 ------------
# id: (construction, area, azimuth, zone)
EXTERIOR_OPAQUE = {
    "W1": ("extwall_S_N", 9.0436, 0.0, "kitchen"),
    "W2": ("extwall_S_N", 8.0524, 0.0, "doorway"),
    "W3": ("extwall_S_N", 12.4384, 0.0, "bedroom"),
    "W4": ("extwall_E", 12.2344, 90.0, "bedroom"),
    "W5": ("extwall_E", 10.2664, 90.0, "bath"),
    "W6": ("extwall_E", 11.2832, 90.0, "child"),
    "W7": ("extwall_S_N", 13.3584, 180.0, "child"),
    "W8": ("extwall_S_N", 14.726, 180.0, "living"),
    "W9": ("extwall_Ws", 16.8428, 270.0, "living"),
    "W10": ("extwall_Wn", 6.2812, 270.0, "living"),
    "W11": ("extwall_Wn", 10.578, 270.0, "kitchen"),
    "W26": ("door", 2.014875, 0.0, "doorway"),
}
# (floor id, ceiling id, zone, area)
SLABS = [("W12", "W13", "kitchen", 10.86825), ("W14", "W15", "doorway", 7.917375),
         ("W16", "W17", "bedroom", 16.43065), ("W18", "W19", "living", 41.153625),
         ("W20", "W21", "corridor", 5.68095), ("W22", "W23", "bath", 8.0754),
         ("W24", "W25", "child", 15.1532)]
# id: (construction, area, room side, other side)
PARTITIONS = {
    "W34": ("intwall_2", 11.0208, "doorway", "kitchen"),
    "W35": ("intwall_1", 11.0208, "bedroom", "doorway"),
    "W36": ("intwall_1", 11.0536, "living", "kitchen"),
    "W37": ("intwall_1", 8.0524, "living", "doorway"),
    "W38": ("intwall_2", 5.9532, "corridor", "bedroom"),
    "W39": ("intwall_2", 8.4624, "bath", "bedroom"),
    "W40": ("intwall_1", 10.0368, "corridor", "living"),
    "W41": ("intwall_2", 10.0368, "bath", "corridor"),
    "W42": ("intwall_2", 5.9532, "child", "corridor"),
    "W43": ("intwall_2", 8.4624, "child", "bath"),
    "W44": ("intwall_1", 11.2832, "child", "living"),
    "W45": ("door", 1.893375, "living", "kitchen"),  # closed
    "W46": ("door", 1.893375, "living", "doorway"),  # closed
    "W47": ("door", 1.893375, "corridor", "bedroom"),  # closed
    "W48": ("door", 1.893375, "corridor", "living"),  # open: a wood leaf, as in IDEAS
    "W49": ("door", 1.893375, "child", "corridor"),  # open
    "W50": ("door", 1.893375, "bath", "corridor"),  # open
    "W51": ("column", 6.56, "kitchen", "kitchen"),
    "W52": ("column", 6.56, "bedroom", "bedroom"),
    "W53": ("column", 6.56, "living", "living"),
    "W54": ("column", 6.56, "child", "child"),
    "W55": ("intwall_1", 1.6236, "bedroom", "living"),
}
# Where the sun through each window lands: the floor of its room.
FLOOR_OF = {zone: floor for floor, _, zone, _ in SLABS}

W9_BL1_DEPTH = 0.34  # int plaster 0.01 + brick 0.30 + former ext plaster 0.03: EPS / old wall


def _surface(zone, h_conv):
    return {"zone": zone, "h_conv": h_conv, "h_rad": H_RAD_IN}


def _exterior(irradiance, absorptance, roughness, emissivity=EMISSIVITY):
    """An outdoor face under the measured facade irradiance (W/m2), its convection DOE-2's at the
    measured wind and its long-wave exchange at its own and the sky's temperatures (docs/model.md
    3.6); the step matrix holds DOE-2's h at the record's mean wind (W/m2/K) and h_rad at 10 C."""
    h_conv = convection.doe2(90.0, MEAN_WIND_SPEED * WIND_FACTOR, roughness)
    return {"type": "exterior", "h_conv": round(float(h_conv), 4), "h_rad": round(H_RAD_OUT * emissivity / EMISSIVITY, 4),
            "solar_absorptance": absorptance, "irradiance": irradiance,
            "convection": {"algorithm": "doe2", "roughness": roughness, "wind_factor": WIND_FACTOR},
            "longwave": {"emissivity": emissivity}}


def window_emissivity(frame_fraction):
    """Long-wave emissivity of a window's outer face: its glass's and its PVC frame's by area."""
    return round(frame_fraction * EMISSIVITY + (1.0 - frame_fraction) * EMISSIVITY_GLASS, 4)


def gap_conductivity():
    """Conductivity (W/m/K) of the argon gap's layer: d times its conductance (W/m2/K) at 10 C with
    15 K across (ISO 15099, docs/model.md 4.1), which the step matrix holds; its Nusselt number is
    the gap's own at 16 mm, whatever the windows' heights (1.54 and 2.37 m)."""
    height = WINDOWS["W31"][5]
    return GAP * glazing.gap_conductance(GAP, height, EMISSIVITY_LOW_E, EMISSIVITY_GLASS, gas=GAP_GAS)


# A window's layers, inside face first: the low-e pane, the argon gap, the clear pane (m)
WINDOW_LAYERS = [("glass", PANE), ("argon_gap", GAP), ("glass", PANE)]


def _component(name, area, tilt, azimuth, layers, nodes, inside, outside, **extra):
    return {"name": name, "area": area, "tilt": tilt, "azimuth": azimuth,
            "layers": [list(layer) for layer in layers], "nodes": nodes,
            "inside": inside, "outside": outside, **extra}


def components(experiment=1):
    """Every component of the ground floor, in IDEAS id order."""
    out = []
    for name, (construction, area, azimuth, zone) in EXTERIOR_OPAQUE.items():
        nodes = NODES["W9"] if name == "W9" else NODES["thin" if construction == "door" else "extwall"]
        out.append(_component(name, area, 90.0, azimuth, CONSTRUCTIONS[construction], nodes,
                              _surface(zone, H_CONV_HORIZONTAL_FLOW),
                              _exterior(FACADE_IRRADIANCE[azimuth], SOLAR_ABSORPTANCE_OUT,
                                        ROUGHNESS_DOOR if construction == "door" else ROUGHNESS_RENDER)))
    for floor, ceiling, zone, area in SLABS:
        out.append(_component(floor, area, 180.0, 0.0, CONSTRUCTIONS["floor"], NODES["slab"],
                              _surface(zone, H_CONV_DOWNWARD_FLOW),
                              {"type": "boundary", "temperature": CELLAR,
                               "h": H_CONV_DOWNWARD_FLOW + H_RAD_IN}))
        out.append(_component(ceiling, area, 0.0, 0.0, CONSTRUCTIONS["ceiling"], NODES["slab"],
                              _surface(zone, H_CONV_UPWARD_FLOW),
                              {"type": "boundary", "temperature": ATTIC,
                               "h": H_CONV_UPWARD_FLOW + H_RAD_IN}))
    for name, (zone, azimuth, area, frame, _, height) in WINDOWS.items():
        # the gap (layer 1 from the inside) between the inner pane's low-e face and the outer's glass
        gap = {"layer": 1, "emissivities": [EMISSIVITY_LOW_E, EMISSIVITY_GLASS], "gas": GAP_GAS}
        extra = {"solar_transmittance": round(G_NORMAL * TAU_DIFFUSE / TAU_NORMAL * (1.0 - frame), 4),
                 "transmitted_solar_to": FLOOR_OF[zone], "window": {"height": height, "gaps": [gap]}}
        if azimuth == 180.0:
            extra["shading"] = SOUTH_SHADING
        elif name in EXPERIMENTS[experiment]["shaded"]:
            extra["shading"] = EXPERIMENTS[experiment]["shaded"][name]
        out.append(_component(name, area, 90.0, azimuth, WINDOW_LAYERS,
                              NODES["thin"], _surface(zone, H_CONV_HORIZONTAL_FLOW),
                              _exterior(FACADE_IRRADIANCE[azimuth], round(SOLAR_ABSORPTANCE_OUT * frame, 4),
                                        ROUGHNESS_GLASS, window_emissivity(frame)),
                              **extra))
    for name, (construction, area, room, other) in PARTITIONS.items():
        nodes = NODES["intwall" if construction.startswith("intwall") else "thin"]
        out.append(_component(name, area, 90.0, 0.0, CONSTRUCTIONS[construction], nodes,
                              _surface(room, H_CONV_HORIZONTAL_FLOW),
                              {"type": "zone", **_surface(other, H_CONV_HORIZONTAL_FLOW)}))
    return sorted(out, key=lambda c: int(c["name"][1:]))


def zones(experiment=1):
    """The seven rooms: IDEAS volumes, no occupants, measured heat inputs, the ventilation path."""
    supply_flow = EXPERIMENTS[experiment]["supply_flow"]
    out = []
    for name, (volume, heat_input) in ZONES.items():
        zone = {"name": name, "volume": volume, "air_change_rate": AIR_CHANGE_RATE,
                "internal_gain": 0.0, "occupied": False, "inside_convection_algorithm": INSIDE_CONVECTION}
        if heat_input:
            zone["heat_input"] = heat_input[0] if len(heat_input) == 1 else heat_input
            zone["heat_input_radiative_fraction"] = HEATER_RADIATIVE_FRACTION
        if name == "living":
            zone["supply"] = {"flow": supply_flow, "temperature": "vent_SUA_corr_AT"}
        inflow = [{"zone": source, "flow": flow} for to, source, flow in airflows(supply_flow) if to == name]
        if inflow:
            zone["airflow_from"] = inflow
        out.append(zone)
    return out


# The inside faces experiment 2 measures besides W9's, each a surface temperature `<prefix>_IS_T`
# and a heat flux `<prefix>_IS_HF` (W/m2): the data's prefix read as room, w(indow) or f(acade),
# orientation. lww, lws and cws are glazing (their flux swings to -200 W/m2 when the sun heats the
# pane), cfs and cfe walls (a few W/m2 into the wall, as W9's). The data do not say which of the
# living room's two south windows lws is: W31, the window, not the door-window W30.
SURFACE_SENSORS = {"W32": "lww", "W31": "lws", "W29": "cws", "W7": "cfs", "W6": "cfe"}


def sensors():
    """Sensor names of the measured channels: each room's air, the three W9 nodes, the inside
    faces experiment 2 measures (`SURFACE_SENSORS` and W9's): `<component>_inside` their
    temperature, `<component>_inside_flux` the heat flux through them (W/m2, into the component)."""
    named = {zone: {"zone": zone} for zone in ZONES}
    thickness = sum(t for _, t in CONSTRUCTIONS["extwall_Ws"])
    named.update({"W9_inside": {"component": "W9", "depth": 0.0},
                  "W9_BL1": {"component": "W9", "depth": W9_BL1_DEPTH},
                  "W9_outside": {"component": "W9", "depth": round(thickness, 6)},
                  "W9_inside_flux": {"component": "W9", "face": "inside", "quantity": "heat_flux"}})
    for component in SURFACE_SENSORS:
        named[f"{component}_inside"] = {"component": component, "face": "inside"}
        named[f"{component}_inside_flux"] = {"component": component, "face": "inside", "quantity": "heat_flux"}
    return named


def building(experiment=1):
    """The whole building file as JSON data, under the protocol of `experiment` (EXPERIMENTS)."""
    materials = {name: {"conductivity": k, "density": rho, "specific_heat": c}
                 for name, (k, rho, c) in MATERIALS.items()}
    materials["glass"] = {"conductivity": GLASS[0], "density": GLASS[1], "specific_heat": GLASS[2]}
    materials["argon_gap"] = {"conductivity": round(gap_conductivity(), 6), "density": GAS_DENSITY,
                              "specific_heat": GAS_SPECIFIC_HEAT}
    return {
        "format": "nodal-building/1",
        "name": "Twin House N2, ground floor (IEA EBC Annex 58)",
        "description": ("The instrumented ground floor of Twin House N2, Holzkirchen, from "
                        "examples/twinhouse_n2/data/exp1/BUILDING.md (IDEAS values, IDEAS areas on "
                        "external dimensions); written by examples/twinhouse_n2/make_building.py, every "
                        "choice stated in examples/twinhouse_n2/README.md."),
        "site": {"latitude": 47.874, "longitude": 11.728, "altitude": 690.0,
                 "timezone": "Etc/GMT-1", "ground_albedo": 0.23},
        "materials": materials,
        "zones": zones(experiment),
        "components": components(experiment),
        "sensors": sensors(),
    }


def text(data=None):
    """building.json's text: the data (default: experiment 1's), indented, with a final newline."""
    return json.dumps(building() if data is None else data, indent=1) + "\n"


def corrected(data, report_path):
    """The building data with the effects a diagnosis added (report.json's "effects", in order),
    each declared at its calibrated values."""
    from nodeforce.model.building_file import parse_building
    from nodeforce.model.effects import EFFECTS
    model = parse_building(data)
    for added in json.loads(Path(report_path).read_text())["effects"]:
        values = {name: p["value"] for name, p in added["parameters"].items()}
        model = EFFECTS[added["effect"]].apply(model, added["target"], values)
    return model.to_json()


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--experiment", type=int, choices=sorted(EXPERIMENTS), default=1)
    parser.add_argument("-o", "--output", type=Path, default=HERE / "building.json")
    parser.add_argument("--corrected-by", help="a diagnosis' report.json whose effects are added")
    args = parser.parse_args()
    data = building(args.experiment)
    args.output.write_text(text(corrected(data, args.corrected_by) if args.corrected_by else data))
