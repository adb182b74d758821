"""The building file's own numerical error: what its discretisation (the nodes of its walls, the
steps of the implicit scheme) makes of a record, which no correction of its physics should be
fitted to (docs/model.md section 5.8).

A wall of a few nodes and steps of up to 5 min are an approximation of the heat equation; the
measured building is the continuum. The error they make is estimated the way a numerical analyst
checks convergence: the same file, node for node, simulated on a grid `REFINEMENT` times finer in
space and with steps of at most `REFERENCE_STEP`, over the same record, from the same history
and burn-in. The difference at the objective's air is an estimate of the file's error that
the sensors' noise does not contain: it is deterministic and follows the weather, so a candidate
effect with a slow parameter (a wall's conductivity, a mass) can fit part of it.
"""
import math
from dataclasses import replace
from itertools import count

import numpy as np

from .building_file import gap_nodes, parse_building

REFINEMENT = 4  # cells of the reference per stretch between two of the file's nodes or layer boundaries
REFERENCE_STEP = 60.0  # s, the reference's longest integration step


def refined(building, cells=REFINEMENT):
    """The building with explicit nodes: each stretch between two of its nodes or layer boundaries
    cut into `cells` equal cells; its own nodes keep their ids (the added ones follow them), so a
    column T<id> or a sensor measures the same point in both. Nodes an effect adds (an internal
    mass, a heater) are numbered after all of them. A window's gas gap keeps its two face nodes
    alone: its conductance follows the panes on either side (`Component.window`), and the gas
    stores no heat a finer grid would resolve."""
    data = building.to_json()
    ids = count(building.own_nodes + 1)
    for raw, c in zip(data["components"], building.components):
        bounds = np.cumsum([t for _, t in c.layers])[:-1]
        # the depth each gas gap starts at: the first of its two face nodes (`gap_nodes`)
        gaps = {c.depths[gap_nodes(c.layers, c.depths, g.layer)[0]] for g in (c.window.gaps if c.window else ())}
        points = sorted([(d, i) for i, d in zip(c.node_ids, c.depths)]
                        + [(float(d), None) for d in bounds if np.abs(np.array(c.depths) - d).min() > 1e-9])
        nodes = []
        for (a, i), (b, _) in zip(points, points[1:]):
            nodes.append({"id": i or next(ids), "depth": a})
            nodes += [{"id": next(ids), "depth": a + (b - a) * k / cells} for k in range(1, 1 if a in gaps else cells)]
        nodes.append({"id": points[-1][1], "depth": points[-1][0]})
        raw["nodes"] = nodes
    for raw, z in zip(data["zones"], building.zones):
        raw["air_node"], raw["radiant_node"] = z.air_node, z.radiant_node
    return parse_building(data, source=f"{building.source} (refined)")


def reference_case(case, building, cells=REFINEMENT, step=REFERENCE_STEP):
    """The case of the refined building (`refined`): the same inputs and history, the
    measurements of the file's own nodes at the same ids, sub-steps of at most `step` (s)."""
    fine = refined(building, cells)
    return fine, replace(case.with_inputs(fine), measured=case.measured[:, :building.own_nodes],
                         substeps=max(case.substeps, math.ceil(case.dt / step - 1e-9)))


def reference(case, building, nodes):
    """(N_t, len(nodes)) the refined reference's temperatures (C) at `nodes` (ids of the file's
    own nodes) at t_1..t_N, simulated as a diagnosis runs `case` (its history, burn-in and steady
    start)."""
    fine, on_fine = reference_case(case, building)
    return on_fine.run(fine, np.asarray(nodes) - 1)


def discretisation_error(case, building, nodes):
    """(N_t, len(nodes)) the file's numerical error at `nodes` (ids), C, at t_1..t_N: the building
    as written minus the refined reference (`reference`), both simulated as a diagnosis runs
    `case`."""
    return case.with_inputs(building).run(building, np.asarray(nodes) - 1) - reference(case, building, nodes)


def share(residual, error, rows=None):
    """The share s in [0, 1] of the file's numerical error `error` (C, the file's run minus the
    continuum's: `discretisation_error`) that least squares finds in `residual` (C, measured
    minus the file's run, the same shape, NaN where not scored), on the `rows` (bool, the same
    shape; every finite one if None): the residual holds -s * error.

    s = 0 says the building behaves as the file's network, s = 1 as the continuum the file
    discretises; between, the error's share the residual holds. A correction fitted to the
    residual plus s * error (measured minus the file's run moved s of the way to the continuum)
    is fitted to what the physics the file declares misses, not to what its discretisation makes
    (`diagnosis.calibrate`)."""
    _, e, r, energy = read_by_share(residual, error, rows)
    return float(np.clip(-(e @ r) / energy, 0.0, 1.0)) if energy > 0.0 else 0.0


def share_slope(residual, error, rows, slopes):
    """(k,) the derivatives of `share` with respect to k parameters the residual moves with, from
    the residual's own derivatives `slopes` (C per unit of each, (residual.size, k) for the
    residual flattened): -(e . dr) / (e . e) on the rows `share` reads, zero where the share is
    held at 0 or 1."""
    keep, e, r, energy = read_by_share(residual, error, rows)
    if energy <= 0.0 or not 0.0 < -(e @ r) / energy < 1.0:
        return np.zeros(slopes.shape[1])
    return -(e @ slopes[keep]) / energy


def read_by_share(residual, error, rows):
    """What `share` reads: the flattened rows it keeps (finite, among `rows` where given), the
    error and the residual there, and the error's energy e . e (C2)."""
    keep = (np.isfinite(residual) & np.isfinite(error) & (True if rows is None else rows)).ravel()
    e = error.ravel()[keep]
    return keep, e, residual.ravel()[keep], float(e @ e)
