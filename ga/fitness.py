"""J of a forcing mask, simulated through the FMU (the search's evaluator).

`FmuFitness` is the picklable factory `ga.search` sends to each worker; the worker calls it
once, extracting and instantiating the FMU once, and then scores every chromosome it is given
by resetting and re-running that one instance, warm-up included; `close()` frees it.
`ModelFitness` scores the same J with the direct model (`model.integrate.simulate`, equal to the
FMU within 1e-9 C) for studies that simulate many thousand masks: the patience measurement and
the paper-mode comparisons (benchmarks/bench_search.py, tests).
"""
import zipfile

import numpy as np

from nodeforce.cosim.fmi2 import FmuInstance
from nodeforce.cosim.run import simulate_fmu
from nodeforce.model.integrate import simulate
from nodeforce.model.network import assemble
from nodeforce.model.score import sum_of_squares


class FmuFitness:
    """Factory of evaluators scoring masks over `chromosome_nodes` by J on `output_node`.

    Parameters
    ----------
    fmu_path : the building's FMU
    case : model.case.Case with the measurements
    chromosome_nodes : node ids, one bit each
    output_node : the measured air node J is computed on
    warmup_days : warm-up passes (PHYSICS.md section 5)
    """

    def __init__(self, fmu_path, case, chromosome_nodes, output_node, warmup_days=2):
        self.fmu_path = str(fmu_path)
        # The slave's module name hashes the building and the model code (fmu_build.build), so a
        # checkpoint keyed on this factory is never resumed against another model.
        with zipfile.ZipFile(self.fmu_path) as fmu:
            self.model_id = fmu.read("resources/slavemodule.txt").decode().strip()
        self.case = case
        self.chromosome_nodes = np.asarray(chromosome_nodes, dtype=int)
        self.output_node = int(output_node)
        self.warmup_days = warmup_days

    def __call__(self):
        return FmuEvaluator(self)


class ModelFitness:
    """Factory of evaluators of the same J as `FmuFitness`, simulated by the direct model.

    Parameters
    ----------
    building : model.building.Building the case belongs to
    case, chromosome_nodes, output_node, warmup_days : as for FmuFitness
    """

    def __init__(self, building, case, chromosome_nodes, output_node, warmup_days=2):
        self.building = building
        self.case = case
        self.chromosome_nodes = np.asarray(chromosome_nodes, dtype=int)
        self.output_node = int(output_node)
        self.warmup_days = warmup_days

    def __call__(self):
        return ModelEvaluator(self)


class _Evaluator:
    """J (C2) of a mask over the spec's chromosome nodes; subclasses simulate the air node."""

    def __init__(self, spec):
        self.spec = spec
        self.measured = spec.case.measured[1:, spec.output_node - 1]

    def J(self, mask):
        force = np.zeros(self.spec.case.measured.shape[1], dtype=bool)
        force[self.spec.chromosome_nodes[np.asarray(mask, dtype=bool)] - 1] = True
        return sum_of_squares(self.measured, self.air(force))


class FmuEvaluator(_Evaluator):
    def __init__(self, spec):
        super().__init__(spec)
        self.instance = FmuInstance(spec.fmu_path)

    def air(self, force):
        """Air temperature (C) at t_1..t_N with the `force` (N,) bool nodes forced."""
        return simulate_fmu(self.instance, self.spec.case, force, self.spec.warmup_days,
                            output_ids=[self.spec.output_node])[:, 0]

    def close(self):
        """Free the FMU instance and remove its extracted files."""
        self.instance.close()


class ModelEvaluator(_Evaluator):
    def __init__(self, spec):
        super().__init__(spec)
        self.network = assemble(spec.building)

    def air(self, force):
        """Air temperature (C) at t_1..t_N with the `force` (N,) bool nodes forced."""
        case = self.spec.case
        return simulate(self.spec.building, self.network, case.U, case.dt, case.measured, force=force,
                        warmup_days=self.spec.warmup_days)[:, self.spec.output_node - 1]
