"""The standalone FMU: the assembled network as data, stepped by generic C code; no Python at
run time (`nodeforce fmu BUILDING --standalone -o MODEL.fmu`).

Python assembles (model.network), C only steps (c/nodeforce_fmu.c, docs/model.md). A shaded
glazing's transmitted sun, the product of two inputs, is data too: which node and inputs, and
its coefficient in each term. So are the coefficients that follow the state (docs/model.md
section 3.6): their nodes (`followed_layout`), and their values, entries of the network after P
that the terms below carry like A's; each step evaluates them with the direct model's C
(model/c/followed.h).

Every parameter stays an FMU parameter: the building's properties and an added effect's
(`model.effects.fmu_parameters`). The network is affine in each of them (a conductivity or
capacity factor scales its component's conductances or capacities, a convection factor its
zone's surface links and its faces' followed A phi, an air change rate a conductance to T_out,
an absorptance, a transmittance or a gain a column of B or q; ground coupling's q = A U T_ground
is bilinear), so it is exported as its value at the declared parameters p0 plus, per set S of
parameters that act together, a term weighted by prod_{j in S} (p_j - p0_j), found from assemblies at the
corners p0 + delta_S: every set of the effect's parameters, each property alone (in batches of
properties that change different nodes' rows, one assembly a batch), and a property with a set
of the effect's where both change the same entries (a conductivity factor under an envelope
factor). Each term keeps only its nonzeros, so the file grows with the parameters'
reach, not with N^2 per parameter. The export checks that form against a direct assembly with
every parameter moved at once, and refuses a network that does not fit it (an InputError naming
the field where the misfit is in a followed coefficient's values).
"""
import itertools

import numpy as np

from nodeforce.model.compiled import FOLLOWED, followed_arrays
from nodeforce.model.effects import fmu_parameters, properties, with_fmu_parameters
from nodeforce.model.errors import InputError
from nodeforce.model.integrate import MAX_STEP
from nodeforce.model.network import assemble

from .compiler import C_DIR, MODEL_C_DIR, library

SOURCES = (C_DIR / "nodeforce_fmu.c", MODEL_C_DIR / "profile.h", MODEL_C_DIR / "followed.h", C_DIR / "fmi2.h",
           C_DIR / "variables.h",
           C_DIR / "resources.h")
IDENTIFIER = "nodeforce_standalone"
NO_LIMIT = 1e30  # an air flow's limit that does not act, in the exported network (K, m/s)
# the building file's field that declares each kind of followed coefficient (`Building.followed_coefficients`)
FOLLOWED_FIELD = {"inside": "inside_convection_algorithm", "outside": "outside.convection",
                  "longwave": "outside.longwave", "windows": "window", "gaps": "window", "pairs": "longwave_followed",
                  "flows": "flow_density", "people": ".people"}


def product_keys(networks):
    """The (node, input a, input b) of every product of inputs in these networks (a shaded
    glazing's transmitted sun, coefficient u_a u_b W), in a fixed order."""
    return sorted({(node, a, b) for network in networks for node, a, b, _ in network.products})


def followed_layout(network):
    """(counts, nodes, columns) of a network's coefficients that follow the state: each kind's
    count and their nodes (int, flat), in `compiled.FOLLOWED`'s order, as c/followed.h reads them
    (their values are the block's last entries, `_block`)."""
    kinds, columns = followed_arrays(network.convection)
    return (tuple(count for count, _, _ in kinds), tuple(int(i) for _, nodes, _ in kinds for i in nodes),
            tuple(columns.tolist()))


def _block(network, keys, layout):
    """C, A, B, q, P (the coefficients, W, of its products at `keys`) and the values of the
    coefficients that follow the state (of `layout`, `followed_layout`) of a network, flat."""
    P = np.zeros(len(keys))
    for node, a, b, coefficient in network.products:
        if (node, a, b) not in keys:
            raise ValueError("a parameter adds a product of inputs the declared network lacks: no standalone export")
        P[keys.index((node, a, b))] += coefficient
    if followed_layout(network) != layout:
        raise ValueError("a parameter changes which faces' coefficients follow the state: no standalone export")
    kinds, _ = followed_arrays(network.convection)
    # an air flow's limit that does not act is infinite in the network; written as NO_LIMIT, any
    # temperature or wind compares with it alike and the corners' differences stay finite
    return np.concatenate([network.C, network.A.ravel(), network.B.ravel(), network.q, P,
                           *(np.clip(values, -NO_LIMIT, NO_LIMIT) for _, _, values in kinds)])


def _rows(network, keys):
    """The node (0-based) of each entry of `_block`: a property changes the rows of its nodes; a
    followed coefficient's values are its (first) face's or air's."""
    n, n_in = network.n_nodes, network.B.shape[1]
    nodes = np.arange(n)
    kinds, _ = followed_arrays(network.convection)
    owners = [np.repeat(faces.reshape(count, -1)[:, 0], width)
              for (count, faces, _), (_, width, _, _) in zip(kinds, FOLLOWED) if count]
    return np.concatenate([nodes, np.repeat(nodes, n), np.repeat(nodes, n_in), nodes,
                           np.array([node for node, _, _ in keys], dtype=int), *owners])


def magnitude(block):
    """The largest |entry| of a flat network (at least 1), a limit that does not act (NO_LIMIT)
    aside: the scale of its tolerances."""
    finite = np.abs(block)
    return max(1.0, finite[finite < NO_LIMIT].max(initial=0.0))


def _batches(reaches):
    """Parameters (indices into `reaches`, sets of rows) in batches whose rows are disjoint:
    greedily, each into the first batch it does not meet."""
    batches, used = [], []
    for j, rows in enumerate(reaches):
        k = next((k for k, taken in enumerate(used) if not taken & rows), None)
        if k is None:
            batches.append([])
            used.append(set())
            k = len(batches) - 1
        batches[k].append(j)
        used[k] |= rows
    return batches


def network_terms(building, effect):
    """(p0, product keys, [(parameter indices, entries, values)]) of the network as a function
    of the FMU's parameters (`fmu_parameters`), multi-affine as the top of this file says: each
    term's nonzeros, at their index in the flat C, A, B, q, P (`_block`); the first term is
    the network at p0.

    The effect's parameters take every corner of theirs. The properties, hundreds on a large
    building, go in batches of properties whose nodes (`Property.reach`) are apart: one assembly
    moves a batch, each property taking the rows of its nodes, and a second, each property moved
    by a different fraction, checks that split.

    Raises ValueError if the network is not of that form (to 1e-9 relative)."""
    if building.switched:
        raise InputError(building.source, "zones", f"{building.switched[0]} follows a schedule: the standalone C FMU "
                         "steps a constant matrix; use the Python FMU")
    start = fmu_parameters(building, effect)
    names = list(start)
    p0 = np.array([start[n] for n in names], dtype=float)
    delta = np.where(p0 != 0.0, -p0 / 2, 1.0)
    base_network = assemble(building)
    inputs, keys, layout = base_network.input_names, product_keys([base_network]), followed_layout(base_network)
    constant = base_network.n_nodes * (2 + base_network.n_nodes + len(inputs)) + len(keys)  # C, A, B, q, P
    reach = {name: {i - 1 for i in p.reach(building, target)} for name, p, target in properties(building)}
    own = [j for j, n in enumerate(names) if n not in reach]  # the effect's parameters

    def corner(fractions):
        """The flat network with parameter j moved by fractions[j] * delta_j."""
        values = {names[j]: p0[j] + f * delta[j] for j, f in fractions.items()}
        return _block(assemble(with_fmu_parameters(building, effect, values), inputs), keys, layout)

    def close(value, exact, why):
        """Whether value is exact to 1e-9 relative; if not, in a followed coefficient's values, the
        building is refused: its FMU parameters act on them otherwise than the C FMU sets them."""
        wrong = np.abs(value - exact) > 1e-9 * magnitude(exact)
        if wrong[constant:].any():
            ends = constant + np.cumsum([count * width for count, (_, width, _, _) in zip(layout[0], FOLLOWED)])
            kind = FOLLOWED[np.searchsorted(ends, np.flatnonzero(wrong[constant:])[0] + constant, side="right")][0]
            where, field = next((w, f) for w, f in building.followed_coefficients if f.endswith(FOLLOWED_FIELD[kind]))
            raise InputError(building.source, field, f"{where}'s coefficient follows the temperatures or the wind, "
                                                     f"and {why}: use the Python FMU")
        return not wrong.any()

    base = corner({})
    scale = magnitude(base)
    corners = {(): base}

    def term(subset):
        """The coefficient of prod_{j in subset} (p_j - p0_j), by inclusion-exclusion."""
        total = 0.0
        for r in range(len(subset) + 1):
            for inner in itertools.combinations(subset, r):
                if inner not in corners:
                    corners[inner] = corner(dict.fromkeys(inner, 1.0))
                total = total + (-1) ** (len(subset) - r) * corners[inner]
        return total / np.prod(delta[list(subset)])

    def sparse(t):
        index = np.flatnonzero(t)
        return index, t[index]

    terms = [((), *sparse(base))]  # (parameter indices, entries, values)
    effect_reach = np.zeros(len(base), dtype=bool)
    subsets = [s for r in range(1, len(own) + 1) for s in itertools.combinations(own, r)]
    for subset in subsets:
        t = term(subset)
        if np.abs(t).max(initial=0.0) > 1e-12 * scale:  # parameters that do act together
            terms.append((subset, *sparse(t)))
            effect_reach |= t != 0.0
    rows = _rows(base_network, keys)
    properties_of = [j for j in range(len(names)) if j not in own]
    for batch in _batches([reach[names[j]] for j in properties_of]):
        batch = [properties_of[k] for k in batch]
        index, change = sparse(corner(dict.fromkeys(batch, 1.0)) - base)
        owner = np.full(len(base_network.C), -1)
        for j in batch:
            owner[list(reach[names[j]])] = j
        who = owner[rows[index]]
        if (who < 0).any():
            raise ValueError("a property changes the network beyond its nodes: no standalone export")
        singles = {j: (index[who == j], change[who == j] / delta[j]) for j in batch}
        fractions = {j: 0.3 + 0.6 * k / len(batch) for k, j in enumerate(batch)}
        split = base.copy()
        for j, f in fractions.items():
            split[singles[j][0]] += f * delta[j] * singles[j][1]
        if not close(split, corner(fractions), "a property acts on it but not affinely apart from the others"):
            raise ValueError("the network is not affine in each of the building's properties apart: "
                             "no standalone export")
        for j in batch:
            entries, values = singles[j]
            if np.abs(values).max(initial=0.0) > 1e-12 * scale:
                terms.append(((j,), entries, values))
            if effect_reach[entries].any():  # with the effect's parameters on the same entries
                corners[(j,)] = base.copy()
                corners[(j,)][entries] += delta[j] * values
                for subset in subsets:
                    both = tuple(sorted((j, *subset)))
                    t = term(both)
                    if np.abs(t).max(initial=0.0) > 1e-12 * scale:
                        terms.append((both, *sparse(t)))
                corners = {key: value for key, value in corners.items() if j not in key}
    exact = corner(dict.fromkeys(range(len(names)), 0.7))
    value = np.zeros(len(base))
    for subset, entries, values in terms:
        value[entries] += np.prod(0.7 * delta[list(subset)]) * values
    if not close(value, exact, "an FMU parameter acts on it but not affinely"):
        raise ValueError("the network is not affine in each of the FMU's parameters: no standalone export")
    return p0, keys, terms


def network_text(building, effect):
    """resources/network.txt: the format c/nodeforce_fmu.c reads (numbers that round-trip)."""
    p0, keys, terms = network_terms(building, effect)
    network = assemble(building)
    n, n_in = building.n_nodes, len(network.input_names)
    counts, nodes, columns = followed_layout(network)
    numbers = lambda values: " ".join(repr(float(v)) for v in np.ravel(values))
    lines = ["nodeforce-network/5",
             f"sizes {n} {n_in} {len(p0)} {len(terms)} {len(keys)} {sum(len(s) for s, _, _ in terms)} "
             f"{sum(len(k) for _, k, _ in terms)}",
             f"p0 {numbers(p0)}",
             f"max_step {MAX_STEP!r}",
             "products " + " ".join(f"{node} {a} {b}" for node, a, b in keys),
             "followed " + " ".join(map(str, (*counts, *columns, *nodes)))]
    for subset, index, values in terms:
        lines.append(" ".join(map(str, ["term", len(subset), *subset, len(index)])))
        lines += [f"{k} {v!r}" for k, v in zip(index.tolist(), values.tolist())]
    lines.append("end")
    return "\n".join(lines) + "\n"


def standalone_files(building, effect, layout):
    """({archive name: bytes}, model identifier, source file names) of the standalone FMU."""
    files = {f"sources/{path.name}": path.read_bytes() for path in SOURCES}
    files["resources/network.txt"] = network_text(building, effect).encode()
    files["resources/names.txt"] = layout.names_file().encode()
    try:
        files[f"binaries/linux64/{IDENTIFIER}.so"] = library("nodeforce_fmu.c", libraries=("m",))
    except RuntimeError as e:
        raise RuntimeError(f"the standalone FMU's linux64 binary is compiled at export: {e}") from None
    return files, IDENTIFIER, ("nodeforce_fmu.c",)
