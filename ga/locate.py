"""`nodeforce locate`: which nodes, forced to their measurements, best explain the indoor air.

Chooses the chromosome (every measured node but the output air node and, by default, the
algebraic radiant nodes, which are no sub-model), builds the FMU, and runs the search with the
measurement noise estimated from the measured air.
"""
import numpy as np

from fmu_build.build import build_fmu
from ga.fitness import FmuFitness
from ga.search import search
from model.errors import InputError
from model.network import assemble
from model.score import noise_level


def output_node(building, case, source):
    """The zone air node J is computed on; it must be measured."""
    air = building.zones[0].air_node
    if air not in case.measured_ids:
        raise InputError(source, f"T{air}", f"the indoor air (node {air}) is not measured; J is computed on it")
    return air


def chromosome_nodes(building, case, source, nodes=None, include_algebraic=False):
    """The nodes the search may force (ids), ascending."""
    air = output_node(building, case, source)
    measured = set(case.measured_ids) - {air}
    if nodes is None:
        algebraic = set(np.flatnonzero(assemble(building).algebraic) + 1)
        return sorted(measured if include_algebraic else measured - algebraic)
    for i in nodes:
        if i == air:
            raise InputError("--nodes", str(i), f"node {i} is the output (indoor air), not a forcing candidate")
        if i not in measured:
            raise InputError(source, f"T{i}", f"node {i} is asked for in --nodes but has no measurement column")
    return sorted(set(nodes))


def locate(building_data, building, case, workdir, *, source="measurements", nodes=None,
           include_algebraic=False, population=30, generations=400, pc=0.8, pm=0.03, seed=0,
           workers=None, scheduler=None, warmup_days=2):
    """Run the forcing search on a case; return the content of locate.json.

    The FMU (`model.fmu`) and the search's checkpoint (`locate.checkpoint.json`) are written in
    `workdir`, so a run stopped midway and started again resumes.
    """
    air = output_node(building, case, source)
    candidates = chromosome_nodes(building, case, source, nodes, include_algebraic)
    if not candidates:
        raise InputError(source, "columns", "no measured node besides the indoor air: nothing to force")
    fmu = build_fmu(building_data, workdir / "model.fmu", source=building.source)
    air_measured = case.measured[1:, air - 1]
    result = search(FmuFitness(fmu, case, candidates, air, warmup_days), candidates,
                    population=population, generations=generations, pc=pc, pm=pm, seed=seed,
                    workers=workers, scheduler=scheduler, checkpoint=workdir / "locate.checkpoint.json",
                    noise_sigma=noise_level(case.measured[:, air - 1]),
                    n_residuals=int(np.isfinite(air_measured).sum()))
    return {"measured_nodes": case.measured_ids, "output_node": air, **result}
