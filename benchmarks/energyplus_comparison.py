"""EnergyPlus's outputs beside nodeforce's nodes: which node each zone and inside face EnergyPlus
reports is, the times EnergyPlus's rows stand for, and the two programs' differences.

A converted building names each component after the EnergyPlus surface it comes from
(iotools/energyplus.py): a surface's inside face is its component's first node (depth 0). Two
surfaces that name each other are one partition, named after one of them; the other's inside
face is the partition's last node, its outer face; so is the face EnergyPlus makes, named
"IZ-<surface>", on the other side of a surface whose outside is a Zone. An InternalMass given to a ZoneList is one
component a zone, named "<mass> <zone>"; EnergyPlus names its surfaces "<zone> <mass>"
(CheckCreatedZoneItemName). A face none of these finds is returned with the reason, never dropped
silently.

EnergyPlus stamps each row with the end of the interval it reports: "01/01  01:00:00" is the hour
00:00-01:00 and "12/31  24:00:00" the year's last. An average variable (a zone's mean air, a
face's temperature) reported hourly is the mean of the hour's time steps; at the time-step
frequency it is the step's result, the state at the step's end.
"""
import numpy as np
import pandas as pd

from nodeforce.iotools.energyplus import SIMPLE_SURFACES, SUBSURFACES, SURFACES

ZONE_AIR = "Zone Mean Air Temperature"
FACE = "Surface Inside Face Temperature"
#: The outside face's heat balance, term by term (W/m2, C, W/m2/K), each face at each step
OUTSIDE = tuple(f"Surface Outside Face {term}" for term in (
    "Incident Solar Radiation Rate per Area", "Incident Beam Solar Radiation Rate per Area",
    "Incident Sky Diffuse Solar Radiation Rate per Area", "Incident Ground Diffuse Solar Radiation Rate per Area",
    "Temperature", "Convection Heat Transfer Coefficient", "Net Thermal Radiation Heat Gain Rate per Area",
    "Conduction Heat Transfer Rate per Area", "Thermal Radiation to Sky Heat Transfer Coefficient",
    "Thermal Radiation to Air Heat Transfer Coefficient", "Thermal Radiation to Ground Heat Transfer Coefficient"))
# the heat transfer surfaces of an IDF, each reported by EnergyPlus under its name
SURFACE_KINDS = {k.upper() for k in (*SURFACES, *SIMPLE_SURFACES, *SUBSURFACES)}


def partners(doc):
    """{surface name (upper case): the surface it names as its other side (upper case)} of the
    IDF's surfaces whose outside is another surface (idfkit document `doc`)."""
    out = {}
    for obj in doc.all_objects:
        if obj.obj_type.upper() in SURFACE_KINDS:
            other = obj.to_dict().get("outside_boundary_condition_object")
            if other:
                out[obj.name.upper()] = str(other).upper()
    return out


def face_nodes(building, names, doc):
    """({face (upper case): node id of its inside face}, {face: why no node}) of the surfaces
    EnergyPlus reports as `names`, in the building converted from the IDF `doc`."""
    first = {c.name.upper(): c.node_ids[0] for c in building.components}
    # a partition's outer face, seen from the zone on its other side
    outer = {c.name.upper(): c.node_ids[-1] for c in building.components if getattr(c.outside, "zone", None)}
    for c in building.components:  # "<mass> <zone>" as EnergyPlus names it, "<zone> <mass>"
        for z in building.zones:
            if c.name.upper().endswith(" " + z.name.upper()) and c.inside.zone == z.name:
                first.setdefault(f"{z.name} {c.name[:-len(z.name) - 1]}".upper(), c.node_ids[0])
    other = partners(doc)
    nodes, unpaired = {}, {}
    for name in names:
        key = name.upper()
        if key in first:
            nodes[key] = first[key]
        elif other.get(key) in outer:
            nodes[key] = outer[other[key]]
        elif key.startswith("IZ-") and key[3:] in outer:  # EnergyPlus's side of a Zone boundary
            nodes[key] = outer[key[3:]]
        else:
            unpaired[key] = ("its partner is not a partition of the building" if key in other
                             else "no component of the building bears its name")
    return nodes, unpaired


def interval_ends(stamps, year):
    """The end (naive local standard time) of each interval EnergyPlus's "MM/DD  hh:mm:ss" stamps
    report, in `year`; "24:00:00" is the next day's midnight."""
    text = pd.Series(stamps).str.strip()
    date = pd.to_datetime(f"{year}/" + text.str.slice(0, 5), format="%Y/%m/%d")
    clock = pd.to_timedelta(text.str.split().str[-1])
    return pd.DatetimeIndex(date + clock, name="time")


def read_outputs(folder, year):
    """(zone air, inside faces): DataFrames (C) of the EnergyPlus run in `folder`, indexed by the
    end of each reported interval (`interval_ends`), columns the zones' and the faces' names
    (upper case)."""
    table = pd.read_csv(folder / "eplusout.csv")
    index = interval_ends(table.iloc[:, 0], year)

    def of(variable):
        columns = [c for c in table.columns if f":{variable} [" in c]
        frame = table[columns].set_axis([c.split(":")[0].strip().upper() for c in columns], axis=1)
        return frame.set_index(index).astype(float)
    return of(ZONE_AIR), of(FACE)


def hourly_means(table):
    """The means over each hour of rows stamped at the end of their step: the row at 01:00 and
    those after 00:00 before it are the hour ending at 01:00, as EnergyPlus averages a variable
    reported hourly."""
    hour_end = table.index.ceil("h")
    return table.groupby(hour_end).mean()


def at_steps(table, per_hour):
    """The rows of a run at small steps that end where a step of `per_hour` an hour ends. Their
    hourly means (`hourly_means`) are the hour's mean as a run at `per_hour` takes it, the mean of
    the states at its steps' ends; the mean of every small step's state sits half a step earlier
    (4.5 min from 60 to 6 an hour), 0.3 K in 600FF's air rising 4 K an hour."""
    return table[(table.index.minute * 60 + table.index.second) % (3600 // per_hour) == 0]


def paired(ours, theirs, lag):
    """(nodeforce, EnergyPlus) on their common times: EnergyPlus's rows `theirs` (indexed by the
    end of the interval they report) compared with nodeforce's samples `ours` (tz-aware) at
    the end less `lag` (half the hour for an hourly mean, nothing for a step's end state)."""
    local = ours.set_axis(ours.index.tz_localize(None), axis=0)
    shifted = theirs.set_axis(theirs.index - pd.Timedelta(lag), axis=0)
    common = local.index.intersection(shifted.index)
    return local.loc[common], shifted.loc[common]


def differences(ours, theirs):
    """(RMSE, mean difference) (K) of nodeforce's series less EnergyPlus's (C, the same length)."""
    d = np.asarray(ours, float) - np.asarray(theirs, float)
    return float(np.sqrt(np.mean(d ** 2))), float(d.mean())
