"""J of a forcing mask, simulated through the FMU (the search's evaluator).

`FmuFitness` is the picklable factory `ga.search` sends to each worker; the worker calls it
once, extracting and instantiating the FMU once, and then scores every chromosome it is given
by resetting and re-running that one instance, warm-up included.
"""
import numpy as np

from nodeforce.cosim.fmi import FmuInstance, content_id
from nodeforce.cosim.run import simulate_fmu


class FmuFitness:
    """Factory of evaluators scoring masks over `chromosome_nodes` by the objective's J.

    Parameters
    ----------
    fmu_path : the building's FMU
    case : model.case.Case with the measurements
    chromosome_nodes : node ids, one bit each
    objective : model.score.Objective, the zones whose measured air J sums
    warmup_days : warm-up passes (PHYSICS.md section 5)
    """

    def __init__(self, fmu_path, case, chromosome_nodes, objective, warmup_days=2):
        self.fmu_path = str(fmu_path)
        # The FMU's GUID hashes its content (fmu_build), so a checkpoint keyed on this factory is
        # never resumed against another model.
        self.model_id = content_id(self.fmu_path)
        self.case = case
        self.chromosome_nodes = np.asarray(chromosome_nodes, dtype=int)
        self.objective = objective
        self.warmup_days = warmup_days

    def __call__(self):
        return FmuEvaluator(self)


class FmuEvaluator:
    def __init__(self, spec):
        self.spec = spec
        self.instance = FmuInstance(spec.fmu_path)
        self.measured = spec.objective.measured(spec.case)

    def J(self, mask):
        force = np.zeros(self.spec.case.measured.shape[1], dtype=bool)
        force[self.spec.chromosome_nodes[np.asarray(mask, dtype=bool)] - 1] = True
        T = simulate_fmu(self.instance, self.spec.case, force, self.spec.warmup_days,
                         output_ids=self.spec.objective.air_nodes)
        return self.spec.objective.J(self.measured, T)
