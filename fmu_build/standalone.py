"""The standalone FMU: the assembled network as data, stepped by generic C code; no Python at
run time (`nodeforce fmu BUILDING --standalone -o MODEL.fmu`).

Python assembles (model.network), C only steps (c/nodeforce_fmu.c, PHYSICS.md section 5). An
added effect's parameters stay FMU parameters: every effect of model.effects changes the network
affinely in each of its parameters (ground coupling's q = A U T_ground is bilinear), so the
network is exported as its value at the declared parameters p0 plus, per set S of parameters, a
term weighted by prod_{j in S} (p_j - p0_j), found from assemblies at the corners p0 + delta_S.
The export checks that form against a direct assembly elsewhere and refuses an effect that does
not fit it.
"""
import itertools
import tempfile
from pathlib import Path

import numpy as np

from nodeforce.model.effects import EFFECTS
from nodeforce.model.network import assemble

from .compiler import C_DIR, compile_library

SOURCES = ("nodeforce_fmu.c", "fmi2.h", "variables.h", "resources.h")
IDENTIFIER = "nodeforce_standalone"


def _arrays(network):
    if network.products:
        raise ValueError("a shaded glazing's transmitted sun is a product of two inputs, which the standalone "
                         "FMU's C step does not compute: no standalone export of a building with 'shading'")
    return (network.C, network.A, network.B, network.q)


def network_terms(building, effect):
    """(p0, [(set of parameter indices, (C, A, B, q))]) of the network as a multi-affine
    function of the effect's parameters; one term (the network) without an effect.

    Raises ValueError if the effect's network is not of that form (to 1e-9 relative)."""
    if effect is None:
        return [], [((), _arrays(assemble(building)))]
    p0 = EFFECTS[effect[0]].read(building, effect[1])
    names = list(p0)
    delta = {name: -value / 2 if value else 1.0 for name, value in p0.items()}

    inputs = assemble(building).input_names  # the FMU's inputs, in the declared building's order

    def at(values):
        return _arrays(assemble(EFFECTS[effect[0]].apply(building, effect[1], values), inputs))

    corners = {}
    for r in range(len(names) + 1):
        for subset in itertools.combinations(range(len(names)), r):
            corners[subset] = at({n: p0[n] + (delta[n] if j in subset else 0.0) for j, n in enumerate(names)})
    terms = []
    for subset in corners:  # inclusion-exclusion over the corners of the subset
        scale = np.prod([delta[names[j]] for j in subset])
        arrays = [sum((-1) ** (len(subset) - len(inner)) * corners[inner][k]
                      for r in range(len(subset) + 1) for inner in itertools.combinations(subset, r)) / scale
                  for k in range(4)]
        if subset and all(np.abs(a).max() <= 1e-12 * max(1.0, np.abs(c).max()) for a, c in zip(arrays, corners[()])):
            continue  # parameters that do not act together (a daily gain's terms): nothing to carry
        terms.append((subset, tuple(arrays)))
    check = {n: p0[n] + 0.7 * delta[n] for n in names}
    expected = at(check)
    for k, exact in enumerate(expected):
        value = sum(np.prod([check[names[j]] - p0[names[j]] for j in subset]) * arrays[k]
                    for subset, arrays in terms)
        if np.abs(value - exact).max() > 1e-9 * max(1.0, np.abs(exact).max()):
            raise ValueError(f"effect {effect[0]} does not change the network affinely in each parameter: "
                             "no standalone export")
    return [p0[n] for n in names], terms


def network_text(building, effect):
    """resources/network.txt: the format c/nodeforce_fmu.c reads (numbers that round-trip)."""
    p0, terms = network_terms(building, effect)
    n = building.n_nodes
    groups = []
    for c in building.components:
        if any(b <= a for a, b in zip(c.depths, c.depths[1:])):
            raise ValueError(f"component {c.name}: node depths must increase for the initial state")
        zone = next(k for k, z in enumerate(building.zones) if z.name == c.inside.zone)
        groups.append((zone, list(zip(c.node_ids, c.depths))))
    numbers = lambda values: " ".join(repr(float(v)) for v in np.ravel(values))
    lines = ["nodeforce-network/1",
             f"sizes {n} {terms[0][1][2].shape[1]} {len(p0)} {len(terms)} {len(building.zones)} {len(groups)}",
             f"p0 {numbers(p0)}"]
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
    with tempfile.TemporaryDirectory(prefix="nodeforce_fmu_") as tmp:
        try:
            compile_library("nodeforce_fmu.c", Path(tmp) / f"{IDENTIFIER}.so", libraries=("m",))
        except RuntimeError as e:
            raise RuntimeError(f"the standalone FMU's linux64 binary is compiled at export: {e}") from None
        files[f"binaries/linux64/{IDENTIFIER}.so"] = (Path(tmp) / f"{IDENTIFIER}.so").read_bytes()
    return files, IDENTIFIER, ("nodeforce_fmu.c",)
