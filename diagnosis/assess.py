"""One candidate effect calibrated and run: the task every worker process or Dask worker of a
round runs (`diagnosis.loop.assess_all`), in a module of its own so that a worker imports what
the calibration needs and nothing of the report (its plots, its tables) or the search."""
from dataclasses import dataclass

import numpy as np

from nodeforce.diagnosis.calibrate import Candidate, Own, calibrate
from nodeforce.diagnosis.policy import POLICY
from nodeforce.model.effects import EFFECTS
from nodeforce.model.network import assemble, slowest_time_constant


@dataclass
class Assessed:
    """One candidate calibrated and run (`assess`): its parameters ({name: {"value", "std", ...}}),
    what the data determine besides, its objective air (N_t, zones) and other sensed nodes
    (`Windows.sensors`) over each whole record (its own component's, which its fit read, on
    each block as the fold without that block predicts them: `assess`), its cross-validation
    folds ({"values", "residuals"} each), the simulations it took and its building file (JSON),
    declared at the calibrated values: the caller writes it, as a Dask worker may not share its
    file system."""
    parameters: dict
    determined: dict
    runs: list
    sensed: list
    folds: list
    simulations: int
    building: dict


def assess(shared, pair):
    """Calibrate one candidate effect, with its cross-validation folds, and run it: a task for a
    worker process or a Dask worker; its `Assessed`. `shared`: what every candidate of the round
    reads (`assess_all`); `pair`: the (effect, target).

    A candidate on a component whose own nodes are measured is fitted to them beside the air
    (`calibrate.Own`); those nodes on each block are then the fold's, fitted without that block,
    so that what the choice reads of its own sensors is, as of the air, what no fit read."""
    building, bases, calibrations, cases, objective, blocks, sensors, numerical, at_sensors, sigma, seed = shared
    effect, target = pair
    candidate = Candidate(building, effect, target, protocols(bases, calibrations, cases))
    own = own_nodes(building, target, sensors, at_sensors, sigma)
    parameters, determined, folds = calibrate(candidate, calibrations, objective, blocks, numerical, own)
    values = [parameters[p.name]["value"] for p in candidate.parameters]
    runs = [candidate.nodes(case, objective.air_nodes, values) for case in cases]
    sensed = [candidate.nodes(case, ids, values).copy() if ids else np.empty((len(case.times) - 1, 0))
              for case, ids in zip(cases, sensors)]
    if own is not None:
        for (record, block), f in zip(blocks, folds):
            rows = np.nonzero(block)[0]
            columns = [sensors[record].index(n) for n in own.ids[record]]
            sensed[record][np.ix_(rows, columns)] = f["own"][rows]
    calibrated = EFFECTS[effect].apply(building, target, {name: p["value"] for name, p in parameters.items()})
    return Assessed(parameters, determined, runs, sensed, folds, candidate.simulations, calibrated.to_json())


def own_nodes(building, target, sensors, numerical, sigma):
    """The measured nodes of the component `target` among each record's other sensors
    (`sensors`, ids), with the file's numerical error there (`numerical`, one (N_t,
    len(sensors)) per record, or None), the noise `sigma` (C) and the component's memory of its
    start as `building` describes it: a `calibrate.Own`; None for a target that is not a
    component or has no node measured."""
    if target not in {c.name for c in building.components}:
        return None
    nodes = building.component(target).node_ids
    columns = columns_among(sensors, set(nodes))
    if not any(columns):
        return None
    memory = POLICY.start_memory * slowest_time_constant(assemble(building), [i - 1 for i in nodes])
    return Own([[ids[j] for j in c] for ids, c in zip(sensors, columns)],
               None if numerical is None else [e[:, c] for e, c in zip(numerical, columns)], sigma, memory)


def columns_among(sensors, nodes):
    """Per record, the columns of its sensors (`sensors`, one list of node ids per record) that
    are among `nodes` (ids)."""
    return [[j for j, node in enumerate(ids) if node in nodes] for ids in sensors]


def protocols(bases, *windows):
    """{id(case): building} of the cases (each sequence of `windows` one per record) of the records
    run under their own protocol's building (`Candidate`)."""
    return {id(c): base for cases in windows for c, base in zip(cases, bases) if base is not None}
