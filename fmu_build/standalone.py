"""The standalone FMU: the assembled network as data, stepped by generic C code; no Python at
run time (`nodeforce fmu BUILDING --standalone -o MODEL.fmu`).

Python assembles (model.network), C only steps (c/nodeforce_fmu.c, docs/model.md). A shaded
glazing's transmitted sun, the product of two inputs, is data too: which node and inputs, and
its coefficient in each term.

Every parameter stays an FMU parameter: the building's properties and an added effect's
(`model.effects.fmu_parameters`). The network is affine in each of them (a conductivity or
capacity factor scales its component's conductances or capacities, a convection factor its
zone's surface links, an air change rate a conductance to T_out, an absorptance, a
transmittance or a gain a column of B or q; ground coupling's q = A U T_ground is bilinear), so
it is exported as its value at the declared parameters p0 plus, per set S of parameters that
act together, a term weighted by prod_{j in S} (p_j - p0_j), found from assemblies at the
corners p0 + delta_S: every set of the effect's parameters, each property alone, and a property
with a set of the effect's where both change the same entries (a conductivity factor under an
envelope factor). Each term keeps only its nonzeros, so the file grows with the parameters'
reach, not with N^2 per parameter. The export checks that form against a direct assembly with
every parameter moved at once, and refuses a network that does not fit it.
"""
import itertools
from pathlib import Path

import numpy as np

from nodeforce import tempdirs
from nodeforce.model.effects import fmu_parameters, with_fmu_parameters
from nodeforce.model.network import assemble

from .compiler import C_DIR, compile_library

SOURCES = ("nodeforce_fmu.c", "fmi2.h", "variables.h", "resources.h")
IDENTIFIER = "nodeforce_standalone"


def product_keys(networks):
    """The (node, input a, input b) of every product of inputs in these networks (a shaded
    glazing's transmitted sun, coefficient u_a u_b W), in a fixed order."""
    return sorted({(node, a, b) for network in networks for node, a, b, _ in network.products})


def _block(network, keys):
    """C, A, B, q and P (the coefficients, W, of its products at `keys`) of a network, flat."""
    P = np.zeros(len(keys))
    for node, a, b, coefficient in network.products:
        if (node, a, b) not in keys:
            raise ValueError("a parameter adds a product of inputs the declared network lacks: no standalone export")
        P[keys.index((node, a, b))] += coefficient
    return np.concatenate([network.C, network.A.ravel(), network.B.ravel(), network.q, P])


def network_terms(building, effect):
    """(p0, product keys, [(parameter indices, flat term)]) of the network as a function of the
    FMU's parameters (`fmu_parameters`), multi-affine as the top of this file says; flat terms
    are C, A, B, q, P (`_block`) and the first is the network at p0.

    Raises ValueError if the network is not of that form (to 1e-9 relative)."""
    start = fmu_parameters(building, effect)
    names = list(start)
    p0 = np.array([start[n] for n in names], dtype=float)
    delta = np.where(p0 != 0.0, -p0 / 2, 1.0)
    base_network = assemble(building)
    inputs, keys = base_network.input_names, product_keys([base_network])
    corners = {}

    def corner(subset, fraction=1.0):
        """The flat network with the parameters of `subset` moved by fraction * delta."""
        if fraction == 1.0 and subset in corners:
            return corners[subset]
        values = {names[j]: p0[j] + fraction * delta[j] for j in subset}
        block = _block(assemble(with_fmu_parameters(building, effect, values), inputs), keys)
        return block

    def term(subset):
        """The coefficient of prod_{j in subset} (p_j - p0_j), by inclusion-exclusion."""
        total = sum((-1) ** (len(subset) - r) * corner(inner) for r in range(len(subset) + 1)
                    for inner in itertools.combinations(subset, r))
        return total / np.prod(delta[list(subset)])

    base = corners[()] = corner(())
    scale = max(1.0, np.abs(base).max(initial=0.0))
    own = [j for j, n in enumerate(names) if effect is not None and n.startswith(f"{effect[0]}.")
           and n not in dict.fromkeys(fmu_parameters(building))]
    terms = [((), base)]
    effect_reach = np.zeros(len(base), dtype=bool)
    for subset in (s for r in range(1, len(own) + 1) for s in itertools.combinations(own, r)):
        for inner in (s for r in range(len(subset) + 1) for s in itertools.combinations(subset, r)):
            if inner not in corners:
                corners[inner] = corner(inner)
        t = term(subset)
        if np.abs(t).max(initial=0.0) > 1e-12 * scale:  # parameters that do act together
            terms.append((subset, t))
            effect_reach |= t != 0.0
    for j in (j for j in range(len(names)) if j not in own):
        single = term((j,))
        if np.abs(single).max(initial=0.0) > 1e-12 * scale:
            terms.append(((j,), single))
        if effect_reach[single != 0.0].any():  # with the effect's parameters on the same entries
            for subset in (s for r in range(1, len(own) + 1) for s in itertools.combinations(own, r)):
                both = tuple(sorted((j, *subset)))
                t = term(both)
                if np.abs(t).max(initial=0.0) > 1e-12 * scale:
                    terms.append((both, t))
        corners.pop((j,), None)
    moved = tuple(range(len(names)))
    exact = corner(moved, 0.7)
    value = sum(np.prod(0.7 * delta[list(subset)]) * t for subset, t in terms)
    if np.abs(value - exact).max(initial=0.0) > 1e-9 * max(1.0, np.abs(exact).max(initial=0.0)):
        raise ValueError("the network is not affine in each of the FMU's parameters: no standalone export")
    return p0, keys, terms


def network_text(building, effect):
    """resources/network.txt: the format c/nodeforce_fmu.c reads (numbers that round-trip)."""
    p0, keys, terms = network_terms(building, effect)
    n, n_in = building.n_nodes, len(assemble(building).input_names)
    numbers = lambda values: " ".join(repr(float(v)) for v in np.ravel(values))
    sparse = [(subset, np.flatnonzero(t)) for subset, t in terms]
    lines = ["nodeforce-network/3",
             f"sizes {n} {n_in} {len(p0)} {len(terms)} {len(keys)} {sum(len(s) for s, _ in sparse)} "
             f"{sum(len(k) for _, k in sparse)}",
             f"p0 {numbers(p0)}",
             "products " + " ".join(f"{node} {a} {b}" for node, a, b in keys)]
    for (subset, t), (_, index) in zip(terms, sparse):
        lines.append(f"term {len(subset)} {' '.join(map(str, subset))} {len(index)}".replace("  ", " "))
        lines += [f"{k} {float(v)!r}" for k, v in zip(index.tolist(), t[index].tolist())]
    lines.append("end")
    return "\n".join(lines) + "\n"


def standalone_files(building, effect, layout):
    """({archive name: bytes}, model identifier, source file names) of the standalone FMU."""
    files = {f"sources/{name}": (C_DIR / name).read_bytes() for name in SOURCES}
    files["resources/network.txt"] = network_text(building, effect).encode()
    files["resources/names.txt"] = layout.names_file().encode()
    with tempdirs.folder("fmu") as tmp:
        try:
            compile_library("nodeforce_fmu.c", Path(tmp) / f"{IDENTIFIER}.so", libraries=("m",))
        except RuntimeError as e:
            raise RuntimeError(f"the standalone FMU's linux64 binary is compiled at export: {e}") from None
        files[f"binaries/linux64/{IDENTIFIER}.so"] = (Path(tmp) / f"{IDENTIFIER}.so").read_bytes()
    return files, IDENTIFIER, ("nodeforce_fmu.c",)
