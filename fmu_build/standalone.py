"""The standalone FMU: the assembled network as data, stepped by generic C code; no Python at
run time (`nodeforce fmu BUILDING --standalone -o MODEL.fmu`).

Python assembles (model.network), C only steps (c/nodeforce_fmu.c, docs/model.md section 5). A
shaded glazing's transmitted sun, the product of two inputs, is data too: which node and inputs,
and its coefficient in each term. An
added effect's parameters stay FMU parameters: every effect of model.effects changes the network
affinely in each of its parameters (ground coupling's q = A U T_ground is bilinear), so the
network is exported as its value at the declared parameters p0 plus, per set S of parameters, a
term weighted by prod_{j in S} (p_j - p0_j), found from assemblies at the corners p0 + delta_S.
The export checks that form against a direct assembly elsewhere and refuses an effect that does
not fit it.
"""
import itertools
from pathlib import Path

import numpy as np

from nodeforce import tempdirs
from nodeforce.model.effects import EFFECTS
from nodeforce.model.network import assemble

from .compiler import C_DIR, compile_library

SOURCES = ("nodeforce_fmu.c", "fmi2.h", "variables.h", "resources.h")
IDENTIFIER = "nodeforce_standalone"


def product_keys(networks):
    """The (node, input a, input b) of every product of inputs in these networks (a shaded
    glazing's transmitted sun, coefficient u_a u_b W), in a fixed order."""
    return sorted({(node, a, b) for network in networks for node, a, b, _ in network.products})


def _arrays(network, keys):
    """(C, A, B, q, P) of a network; P the coefficients (W) of its products at `keys`."""
    P = np.zeros(len(keys))
    for node, a, b, coefficient in network.products:
        if (node, a, b) not in keys:
            raise ValueError("the effect adds a product of inputs its declared network lacks: no standalone export")
        P[keys.index((node, a, b))] += coefficient
    return (network.C, network.A, network.B, network.q, P)


def network_terms(building, effect):
    """(p0, product keys, [(set of parameter indices, (C, A, B, q, P))]) of the network as a
    multi-affine function of the effect's parameters; one term (the network) without an effect.
    P holds the coefficients of the products of inputs at the keys (`product_keys`).

    Raises ValueError if the effect's network is not of that form (to 1e-9 relative)."""
    if effect is None:
        network = assemble(building)
        keys = product_keys([network])
        return [], keys, [((), _arrays(network, keys))]
    p0 = EFFECTS[effect[0]].read(building, effect[1])
    names = list(p0)
    delta = {name: -value / 2 if value else 1.0 for name, value in p0.items()}

    inputs = assemble(building).input_names  # the FMU's inputs, in the declared building's order

    def at(values):
        return assemble(EFFECTS[effect[0]].apply(building, effect[1], values), inputs)

    networks = {}
    for r in range(len(names) + 1):
        for subset in itertools.combinations(range(len(names)), r):
            networks[subset] = at({n: p0[n] + (delta[n] if j in subset else 0.0) for j, n in enumerate(names)})
    keys = product_keys(networks.values())
    corners = {subset: _arrays(network, keys) for subset, network in networks.items()}
    terms = []
    for subset in corners:  # inclusion-exclusion over the corners of the subset
        scale = np.prod([delta[names[j]] for j in subset])
        arrays = [sum((-1) ** (len(subset) - len(inner)) * corners[inner][k]
                      for r in range(len(subset) + 1) for inner in itertools.combinations(subset, r)) / scale
                  for k in range(5)]
        if subset and all(np.abs(a).max(initial=0.0) <= 1e-12 * max(1.0, np.abs(c).max(initial=0.0))
                          for a, c in zip(arrays, corners[()])):
            continue  # parameters that do not act together (a daily gain's terms): nothing to carry
        terms.append((subset, tuple(arrays)))
    check = {n: p0[n] + 0.7 * delta[n] for n in names}
    expected = _arrays(at(check), keys)
    for k, exact in enumerate(expected):
        value = sum(np.prod([check[names[j]] - p0[names[j]] for j in subset]) * arrays[k]
                    for subset, arrays in terms)
        if np.abs(value - exact).max(initial=0.0) > 1e-9 * max(1.0, np.abs(exact).max(initial=0.0)):
            raise ValueError(f"effect {effect[0]} does not change the network affinely in each parameter: "
                             "no standalone export")
    return [p0[n] for n in names], keys, terms


def network_text(building, effect):
    """resources/network.txt: the format c/nodeforce_fmu.c reads (numbers that round-trip)."""
    p0, keys, terms = network_terms(building, effect)
    n = building.n_nodes
    groups = []
    for c in building.components:
        if any(b <= a for a, b in zip(c.depths, c.depths[1:])):
            raise ValueError(f"component {c.name}: node depths must increase for the initial state")
        zone = next(k for k, z in enumerate(building.zones) if z.name == c.inside.zone)
        groups.append((zone, list(zip(c.node_ids, c.depths))))
    # a node a zone effect adds is a group of one, never measured: it starts with the zone's air
    zone_index = {z.name: k for k, z in enumerate(building.zones)}
    groups += [(zone_index[zone], [(i, 0.0)]) for i, (zone, _) in building.added_nodes.items()]
    numbers = lambda values: " ".join(repr(float(v)) for v in np.ravel(values))
    lines = ["nodeforce-network/2",
             f"sizes {n} {terms[0][1][2].shape[1]} {len(p0)} {len(terms)} {len(building.zones)} {len(groups)} "
             f"{len(keys)}",
             f"p0 {numbers(p0)}",
             "products " + " ".join(f"{node} {a} {b}" for node, a, b in keys)]
    for subset, arrays in terms:
        lines.append(f"term {sum(1 << j for j in subset)}")
        lines += [numbers(a) for a in arrays]
    lines.append("zones " + " ".join(f"{z.air_node - 1} {z.radiant_node - 1}" for z in building.zones))
    lines.append("components")
    lines += [f"{zone} {len(nodes)} " + " ".join(f"{i - 1} {float(d)!r}" for i, d in nodes) for zone, nodes in groups]
    lines.append("end")
    return "\n".join(lines) + "\n"


def standalone_files(building, effect):
    """({archive name: bytes}, model identifier, source file names) of the standalone FMU."""
    files = {f"sources/{name}": (C_DIR / name).read_bytes() for name in SOURCES}
    files["resources/network.txt"] = network_text(building, effect).encode()
    with tempdirs.folder("fmu") as tmp:
        try:
            compile_library("nodeforce_fmu.c", Path(tmp) / f"{IDENTIFIER}.so", libraries=("m",))
        except RuntimeError as e:
            raise RuntimeError(f"the standalone FMU's linux64 binary is compiled at export: {e}") from None
        files[f"binaries/linux64/{IDENTIFIER}.so"] = (Path(tmp) / f"{IDENTIFIER}.so").read_bytes()
    return files, IDENTIFIER, ("nodeforce_fmu.c",)
