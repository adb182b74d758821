"""`nodeforce locate`: which nodes, forced to their measurements, best explain the indoor air.

Chooses the chromosome (every measured node but the output air node and, by default, the
algebraic radiant nodes, which are no sub-model), builds the FMU, and runs the search with the
measurement noise estimated from the measured air.
"""
import numpy as np
from scipy.sparse.csgraph import shortest_path

from nodeforce.fmu_build.build import build_fmu
from nodeforce.ga.fitness import FmuFitness
from nodeforce.ga.search import PATIENCE, search
from nodeforce.model.errors import InputError
from nodeforce.model.network import assemble
from nodeforce.model.score import noise_level


def output_node(building, case, source):
    """The zone air node J is computed on; it must be measured."""
    air = building.zones[0].air_node
    if air not in case.measured_ids:
        raise InputError(source, f"T{air}", f"the indoor air (node {air}) is not measured; J is computed on it")
    return air


def links_to(network, node):
    """Number of conductances between each node and `node` (ids 1..N -> index 0..N-1)."""
    coupled = (network.A != 0) & ~np.eye(network.n_nodes, dtype=bool)
    return shortest_path(coupled, unweighted=True, indices=node - 1)


def chromosome_nodes(building, case, source, nodes=None, include_algebraic=False):
    """The nodes the search may force (ids), nearest the air node first, then by id.

    The order is the search's preference between nodes whose scores the noise cannot separate:
    forcing a node nearer the zone cuts off more of the sub-model behind it (the inside surface
    isolates the whole component, a node deeper in cuts only the layers beyond).
    """
    air = output_node(building, case, source)
    network = assemble(building)
    measured = set(case.measured_ids) - {air}
    if nodes is None:
        algebraic = set(np.flatnonzero(network.algebraic) + 1)
        chosen = measured if include_algebraic else measured - algebraic
    else:
        for i in nodes:
            if i == air:
                raise InputError("--nodes", str(i), f"node {i} is the output (indoor air), not a forcing candidate")
            if i not in measured:
                raise InputError(source, f"T{i}", f"node {i} is asked for in --nodes but has no measurement column")
        chosen = set(nodes)
    distance = links_to(network, air)
    return sorted(chosen, key=lambda i: (distance[i - 1], i))


def locate(building_data, building, case, workdir, *, source="measurements", nodes=None,
           include_algebraic=False, population=30, generations=400, pc=0.8, pm=0.03, seed=0,
           patience=PATIENCE, seeded=True, workers=None, scheduler=None, warmup_days=2, progress=None):
    """Run the forcing search on a case; return the content of locate.json.

    The FMU (`model.fmu`) and the search's checkpoint (`locate.checkpoint.json`) are written in
    `workdir`, so a run stopped midway and started again resumes. `progress` is called after
    every generation with (generation, total, best J, unique evaluations). patience and seeded
    choose the search (ga.search: the defaults stop at convergence; ga.search.PAPER's values
    give the paper's search).
    """
    air = output_node(building, case, source)
    candidates = chromosome_nodes(building, case, source, nodes, include_algebraic)
    if not candidates:
        raise InputError(source, "columns", "no measured node besides the indoor air: nothing to force")
    fmu = build_fmu(building_data, workdir / "model.fmu", source=building.source)
    air_measured = case.measured[1:, air - 1]
    result = search(FmuFitness(fmu, case, candidates, air, warmup_days), candidates,
                    population=population, generations=generations, pc=pc, pm=pm, seed=seed,
                    patience=patience, seeded=seeded,
                    workers=workers, scheduler=scheduler, checkpoint=workdir / "locate.checkpoint.json",
                    progress=progress,
                    noise_sigma=noise_level(case.measured[:, air - 1]),
                    n_residuals=int(np.isfinite(air_measured).sum()))
    return {"measured_nodes": case.measured_ids, "output_node": air, **result}
