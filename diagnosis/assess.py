"""One candidate effect calibrated and run: the task every worker process or Dask worker of a
round runs (`diagnosis.loop.assess_all`), in a module of its own so that a worker imports what
the calibration needs and nothing of the report (its plots, its tables) or the search."""
from dataclasses import dataclass, field

import numpy as np

from nodeforce.diagnosis.calibrate import Candidate, Own, calibrate
from nodeforce.model.network import assemble, slowest_time_constant


@dataclass
class Assessed:
    """One candidate calibrated and run (`assess`): its parameters ({name: {"value", "std", ...}}),
    what the data determine besides, its objective air (N_t, zones) and other sensed nodes
    (`Windows.sensors`) over each whole record (its own component's, which its fit read, on
    each block as the fold without that block predicts them: `assess`), its cross-validation
    folds ({"values", "residuals"} each), the simulations it took and its building file (JSON),
    declared at the calibrated values: the caller writes it, as a Dask worker may not share its
    file system. `beside`: where the model's effects were refitted together with it, their
    parameters so refitted, by label ({label: {name: {"value", "std", ...}}}); None otherwise."""
    parameters: dict
    determined: dict
    runs: list
    sensed: list
    folds: list
    simulations: int
    building: dict
    beside: dict = None


@dataclass
class RoundInputs:
    """What every candidate of a round reads (`assess`), sent once to each worker: the model's
    building and each record's protocol's (`bases`), the records' calibration windows and whole
    cases, the objective, the cross-validation blocks, each record's other sensed nodes (ids),
    the file's numerical error at the objective air and at those sensors (one array per record
    each, or None), the air sensors' noise sd (C), the seed, the effects the model holds that are
    refitted together with each candidate ((effect, target)) with those of their parameters
    `held` ({label: names}) kept as they are (`calibrate.Candidate`), the
    `diagnosis.policy.Policy`, and whether each fit estimates the records' start (`started`:
    an earlier round chose it, `diagnosis.selection.decide`)."""
    building: object
    bases: list
    calibrations: list
    cases: list
    objective: object
    blocks: list
    sensors: list
    numerical: list
    at_sensors: list
    sigma: float
    seed: int
    policy: object
    beside: tuple = ()
    held: dict = field(default_factory=dict)
    started: bool = False

    @classmethod
    def of(cls, model, windows, objective, sigma, seed, beside=(), held=None, started=False):
        """The inputs of a round adding to `model` (`loop.Model`) on the `windows`, under their policy."""
        return cls(model.building, model.bases, windows.calibrations, windows.cases, objective, windows.blocks,
                   windows.sensors, windows.calibration_numerical(), windows.calibration_numerical(sensors=True),
                   sigma, seed, windows.policy, tuple(beside), held or {}, started)


def assess(inputs, pair):
    """Calibrate one candidate effect, with its cross-validation folds, and run it: a task for a
    worker process or a Dask worker; its `Assessed`. `inputs`: what every candidate of the round
    reads (`RoundInputs`), the effects the model holds that are refitted together with it among
    them (`Candidate`'s `beside` and `held`); `pair`: the (effect, target).

    A candidate on a component whose own nodes are measured is fitted to them beside the air
    (`calibrate.Own`); those nodes on each block are then the fold's, fitted without that block,
    so that what the choice reads of its own sensors is, as of the air, what no fit read."""
    building, bases, calibrations, cases = inputs.building, inputs.bases, inputs.calibrations, inputs.cases
    objective, blocks, sensors, beside = inputs.objective, inputs.blocks, inputs.sensors, inputs.beside
    effect, target = pair
    candidate = Candidate(building, effect, target, protocols(bases, calibrations, cases), beside, inputs.held)
    own = own_nodes(building, [target, *(t for _, t in beside)], sensors, inputs.at_sensors, inputs.sigma,
                    inputs.policy)
    fitted, determined, folds = calibrate(candidate, calibrations, objective, blocks, inputs.numerical, own,
                                          inputs.policy, inputs.sigma, inputs.started)
    values = [fitted[name]["value"] for name in candidate.names]
    zones = len(objective.air_nodes)
    # the objective air and the other sensors (never the objective air) in one run of each record
    every = [candidate.nodes(case, [*objective.air_nodes, *ids], values) for case, ids in zip(cases, sensors)]
    runs = [run[:, :zones].copy() for run in every]
    sensed = [run[:, zones:].copy() for run in every]
    if own is not None:
        for (record, block), f in zip(blocks, folds):
            rows = np.nonzero(block)[0]
            columns = [sensors[record].index(n) for n in own.ids[record]]
            sensed[record][np.ix_(rows, columns)] = f["own"][rows]
    parameters, refitted = candidate.by_effect(fitted)
    return Assessed(parameters, determined, runs, sensed, folds, candidate.simulations,
                    candidate.built(values).to_json(), refitted or None)


def own_nodes(building, targets, sensors, numerical, sigma, policy):
    """The measured nodes of the components among `targets` among each record's other sensors
    (`sensors`, ids), with the file's numerical error there (`numerical`, one (N_t,
    len(sensors)) per record, or None), the noise `sigma` (C) and the components' memory of their
    start as `building` describes them (the slowest's, `policy.start_memory` of its time
    constants): a `calibrate.Own`; None where no target
    is a component or none has a node measured. Effects refitted together read the own nodes of
    each, as each one's own fit did."""
    components = {c.name for c in building.components}
    nodes = [i for target in targets if target in components for i in building.component(target).node_ids]
    if not nodes:
        return None
    columns = columns_among(sensors, set(nodes))
    if not any(columns):
        return None
    memory = policy.start_memory * slowest_time_constant(assemble(building), [i - 1 for i in nodes])
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
