"""The zone's and the windows' heat balance term by term beside EnergyPlus's own outputs (issue
74, item 1): the IDF `bench_energyplus` runs, with EnergyPlus, at 60 steps an hour (its answer
converged in time), reporting besides each hour the terms below, and nodeforce's counterpart of each computed from its network, its inputs and its
simulated temperatures (the direct model on the EPW at its site, at the half hour), both over the
same Denver year:

- each inside face: its temperature, the sun it absorbs ("Surface Inside Face Solar Radiation
  Heat Gain Rate per Area" x its area), its convective coefficient and the heat the air gives it,
  the net long-wave it gets from the zone's other faces;
- each window: the sun on it, the sun it lets in and the sun its panes absorb;
- each zone: its air and the heat its infiltration carries out.

Per model and term, the year's mean in each program and the hourly RMSE of their difference:
OUT/<model>_terms.csv and the Markdown table printed.

    python benchmarks/energyplus_terms.py [OUT] [--only MODEL ...]   (default out/energyplus_terms, 600FF)
"""
import argparse
import sys
from pathlib import Path

import idfkit
import numpy as np
import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench_energyplus as bench  # noqa: E402
from energyplus_comparison import FACE, ZONE_AIR, face_nodes, interval_ends  # noqa: E402

from nodeforce.api import convert_idf  # noqa: E402
from nodeforce.iotools.weather import read_weather  # noqa: E402
from nodeforce.model.case import measured_case, simulate_building  # noqa: E402
from nodeforce.model.convection import iso15099_inside, lagged_excess, tarp_inside_faces  # noqa: E402
from nodeforce.model.longwave import pair_coefficient  # noqa: E402
from nodeforce.model.network import air_conductance, assemble, outdoor_density_ratio  # noqa: E402

SUN_IN = "Surface Inside Face Solar Radiation Heat Gain Rate per Area"
H_IN = "Surface Inside Face Convection Heat Transfer Coefficient"
CONVECTION = "Surface Inside Face Convection Heat Gain Rate"
LONGWAVE = "Surface Inside Face Net Surface Thermal Radiation Heat Gain Rate"
INCIDENT = "Surface Outside Face Incident Solar Radiation Rate per Area"
TRANSMITTED = "Surface Window Transmitted Solar Radiation Rate"
PANES = "Surface Window Total Glazing Layers Absorbed Solar Radiation Rate"
INFILTRATION = ("Zone Infiltration Sensible Heat Loss Energy", "Zone Infiltration Sensible Heat Gain Energy")
VARIABLES = (SUN_IN, H_IN, CONVECTION, LONGWAVE, INCIDENT, TRANSMITTED, PANES, *INFILTRATION,
             "Surface Window Heat Gain Rate", "Surface Window Heat Loss Rate",
             "Surface Window Inside Face Glazing Zone Convection Heat Gain Rate")
SUN_COLUMNS = ("I_", "It_", "Itb_", "Itd_", "Iao_", "Iai_")


def energyplus_hourly(folder, year):
    """{variable: DataFrame by key (upper case)} of the hourly outputs in `folder`, each row at
    the middle of the hour it reports."""
    table = pd.read_csv(folder / "eplusout.csv")
    table.columns = table.columns.str.strip()
    hourly = table[[c for c in table.columns if c.endswith("(Hourly)")]]
    hourly = hourly.set_index(interval_ends(table.iloc[:, 0], year) - pd.Timedelta("30min")).dropna()
    out = {}
    for column in hourly.columns:
        key, rest = column.split(":", 1)
        out.setdefault(rest.split(" [")[0], {})[key.strip().upper()] = hourly[column].astype(float)
    return {variable: pd.DataFrame(series) for variable, series in out.items()}


def nodeforce_run(building, weather):
    """(network, inputs U DataFrame, temperatures T DataFrame), both at the simulated times (naive
    local), of the building under the hourly weather."""
    network = assemble(building)
    case = measured_case(building, weather)
    T = simulate_building(building, weather, steady_start=True)  # started as EnergyPlus starts
    T.index = T.index.tz_localize(None)
    U = pd.DataFrame(case.U[-len(T):], index=T.index, columns=network.input_names)
    return network, U, T


def sun_sources(network, U):
    """(rows, N) W: the part of each node's sources that the sun gives (the sources less those
    with every irradiance input at 0, so that a shaded sun's products count)."""
    dark = U.to_numpy(float).copy()
    dark[:, [k for k, n in enumerate(network.input_names) if n.startswith(SUN_COLUMNS)]] = 0.0
    return network.sources(U.to_numpy(float)) - network.sources(dark)


def inside_coefficients(network, T):
    """{face node id: (rows,) W/m2/K} of the faces whose inside convection follows the state
    (docs/model.md 3.6): TARP, or a window's ISO 15099, at each hour's face-to-air difference,
    about the step matrix's h0 as the network's lagged source takes it (`lagged_excess`)."""
    conv, out = network.convection, {}
    if conv is None:
        return out
    temperatures = T.to_numpy(float)  # columns T1..TN
    for (face, air), (_, h0, cos_up) in zip(conv.inside_nodes, conv.inside):
        dT = temperatures[:, face] - temperatures[:, air]
        out[face + 1] = h0 + lagged_excess(tarp_inside_faces(dT, cos_up), h0)
    for (face, air), (_, h0, height, tilt, pressure) in zip(conv.window_nodes, conv.windows):
        dT = temperatures[:, face] - temperatures[:, air]
        out[face + 1] = h0 + lagged_excess(iso15099_inside(dT, temperatures[:, air], height, tilt, pressure), h0)
    return out


def exchange_conductances(network, T):
    """{(a, b) node ids: (rows,) W/K} of each pair of faces whose long-wave exchange follows their
    temperatures (a followed ScriptF, docs/model.md 3.6), about the step matrix's G0 as the network's
    lagged source takes it; pairs not listed exchange through the step matrix's A alone."""
    conv, out = network.convection, {}
    if conv is None:
        return out
    temperatures = T.to_numpy(float)
    for (a, b), (exchange, g0) in zip(conv.pair_nodes, conv.pairs):
        G = g0 + lagged_excess(exchange * pair_coefficient(temperatures[:, a], temperatures[:, b]), g0)
        out[(a + 1, b + 1)] = out[(b + 1, a + 1)] = G
    return out


def multipliers(doc):
    """{surface name (upper case): its Multiplier} of the IDF's windows and doors that declare one."""
    return {o.name.upper(): float(o.to_dict()["multiplier"]) for o in doc.all_objects
            if o.obj_type.upper().startswith(("FENESTRATIONSURFACE", "WINDOW", "DOOR", "GLAZEDDOOR"))
            and o.to_dict().get("multiplier") not in (None, "")}


def terms(name, building, doc, network, U, T, theirs):
    """Rows (model, zone, key, term, nodeforce mean, EnergyPlus mean, hourly RMSE, unit). A window
    of Multiplier m is one component of m times its area in nodeforce; EnergyPlus reports its
    "Surface Window" rates for one of the m, and nodeforce's are divided by m beside them."""
    copies = multipliers(doc)
    when = T.index.intersection(theirs[ZONE_AIR].index)
    T, U = T.loc[when], U.loc[when]
    sun = pd.DataFrame(sun_sources(network, U), index=when)
    nodes_T = T[[f"T{i}" for i in range(1, network.n_nodes + 1)]]
    followed, exchange = inside_coefficients(network, nodes_T), exchange_conductances(network, nodes_T)
    rows = []

    def row(zone, key, term, ours, ep, unit):
        ours, ep = np.asarray(ours, float), np.asarray(ep, float)
        rows.append((name, zone, key, term, ours.mean(), ep.mean(), float(np.sqrt(np.mean((ours - ep) ** 2))), unit))

    def add(zone, key, term, ours, variable, scale=1.0, unit="W"):
        if variable in theirs and key in theirs[variable]:
            row(zone, key, term, ours, theirs[variable][key].loc[when].to_numpy(float) * scale, unit)

    nodes, _ = face_nodes(building, theirs[FACE].columns, doc)
    by_node = {i: c for c in building.components for i in c.node_ids}
    for z in building.zones:
        air = T[f"T{z.air_node}"].to_numpy(float)
        zone = z.name.upper()
        add(zone, zone, "air (C)", air, ZONE_AIR, unit="C")
        faces = building.facing(z.name)
        for key, node in nodes.items():
            if node not in faces:
                continue
            c, s = by_node[node], node - 1
            Ts = T[f"T{node}"].to_numpy(float)
            h = followed.get(node, np.full(len(Ts), network.A[s, z.air_node - 1] / c.area))
            add(zone, key, "inside face (C)", Ts, FACE, unit="C")
            add(zone, key, "sun absorbed inside", sun[s], SUN_IN, c.area)
            add(zone, key, "convective coefficient", h, H_IN, unit="W/m2/K")
            add(zone, key, "convection from the air", c.area * h * (air - Ts), CONVECTION)
            add(zone, key, "net long-wave from the faces",
                sum(exchange.get((node, j), network.A[s, j - 1]) * (T[f"T{j}"].to_numpy(float) - Ts)
                    for j in faces if j != node), LONGWAVE)
            if c.solar_transmittance and node == c.node_ids[0]:
                names = [n for n, _ in c.sun_inputs if n != c.irradiance_input]
                incident = U[f"I_{c.name}"].to_numpy(float)
                add(zone, key, "sun on the window (W/m2)", incident, INCIDENT, unit="W/m2")
                one = c.area / copies.get(key, 1.0)
                add(zone, key, "sun let in", c.solar_transmittance * one * U[names or [f"I_{c.name}"]].sum(axis=1),
                    TRANSMITTED)
                add(zone, key, "sun the panes absorb",
                    one * (U[c.absorbed_input("outside")].to_numpy(float) * c.outside.solar_absorptance
                           + U[c.absorbed_input("inside")].to_numpy(float) * c.inner_solar_absorptance), PANES)
        # the flow carried at the outdoor air's density where the site says so, as the network does
        T_out = U["T_out"].to_numpy(float)
        density = outdoor_density_ratio(T_out) if building.site.get("flow_density") == "outdoor" else 1.0
        g = air_conductance(z.volume * z.air_change_rate, building.site.get("air_density", 1.2)) * density
        if INFILTRATION[0] in theirs and zone in theirs[INFILTRATION[0]]:
            out = (theirs[INFILTRATION[0]][zone] - theirs[INFILTRATION[1]][zone]).loc[when] / 3600.0
            row(zone, zone, "infiltration out", g * (air - T_out), out, "W")
    return rows


def markdown(table):
    lines = ["| model | zone | face | term | nodeforce mean | EnergyPlus mean | hourly RMSE | unit |",
             "|---|---|---|---|---|---|---|---|"]
    for r in table.itertuples(index=False):
        lines.append(f"| {r.model} | {r.zone} | {r.key} | {r.term} | {r.nodeforce:.2f} | {r.energyplus:.2f} | "
                     f"{r.rmse:.2f} | {r.unit} |")
    return "\n".join(lines)


def main(out, epw, only):
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    # the EPW read as EnergyPlus reads it, at its site as EnergyPlus's run is (as `bench_energyplus`)
    weather = read_weather(epw, year=bench.YEAR)
    for name in only:
        doc = bench.with_steps(bench.models()[name]())
        idfkit.save_idf(doc, str(out / f"{name}.idf"))
        building = convert_idf(out / f"{name}.idf")
        folder = out / name
        folder.mkdir(parents=True, exist_ok=True)
        # EnergyPlus converged in time: its hour's mean of sixty 1-min states is its state at the
        # hour's middle, to which nodeforce's is set; at the IDF's 6 steps its own step's error
        # (0.5 K in 600FF's air) would be most of each hourly difference
        theirs = bench.to_energyplus_25(bench.with_steps(bench.models()[name](), bench.FINE_STEPS))
        for variable in (ZONE_AIR, FACE, *VARIABLES):
            theirs.add("Output:Variable", "", {"key_value": "*", "variable_name": variable, "reporting_frequency": "Hourly"})
        idfkit.save_idf(theirs, str(folder / "model_25_2.idf"))
        bench.run_energyplus(folder / "model_25_2.idf", folder, epw)
        table = pd.DataFrame(terms(name, building, doc, *nodeforce_run(building, weather),
                                   energyplus_hourly(folder, bench.YEAR)),
                             columns=["model", "zone", "key", "term", "nodeforce", "energyplus", "rmse", "unit"])
        table.to_csv(out / f"{name}_terms.csv", index=False, float_format="%.3f")
        print(markdown(table), flush=True)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", nargs="?", default=bench.ROOT / "out" / "energyplus_terms", type=Path)
    parser.add_argument("--only", nargs="+", default=["600FF"], choices=list(bench.models()))
    args = parser.parse_args()
    main(args.out, bench.package_weather(), args.only)
