"""J of a forcing mask, simulated through the FMU (the search's evaluator).

`FmuFitness` is the picklable factory `ga.search` sends to each worker; the worker calls it
once, extracting and instantiating the FMU once, and then scores every chromosome it is given
by resetting and re-running that one instance, warm-up included; `close()` frees it.
`RecordsFitness` sums J over several records of one building, each through its own FMU (a record
run under another protocol has its own building file). `ModelFitness` scores the same J with the direct model (`model.integrate.simulate`, equal to the
FMU within 1e-9 C) for studies that simulate many thousand masks: the patience measurement and
the paper-mode comparisons (benchmarks/bench_search.py, tests).
"""
import numpy as np

from nodeforce.cosim.fmi import FmuInstance, content_id
from nodeforce.cosim.run import CaseRuns
from nodeforce.model.integrate import STEADY_STEP, ImplicitEuler, history_block, simulate
from nodeforce.model.network import assemble


class FmuFitness:
    """Factory of evaluators scoring masks over `chromosome_nodes` by the objective's J.

    Parameters
    ----------
    fmu_path : the building's FMU
    case : model.case.Case with the measurements
    chromosome_nodes : node ids, one bit each
    objective : model.score.Objective, the zones whose measured air J sums
    warmup_days : warm-up passes (docs/model.md section 5)
    """

    keeps_residuals = True  # its evaluators give residuals(mask): the paired test (ga.parsimony.Paired)

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


class RecordsFitness:
    """Factory of evaluators scoring a mask on several records of one building: the sum of each
    record's J (`FmuFitness`, all over the same chromosome), each record's mask nodes forced where
    that record measures them (a node a record does not measure stays computed there), and the
    records' residuals stacked for the paired comparison.

    Parameters
    ----------
    parts : FmuFitness of each record, their chromosome_nodes equal
    """

    keeps_residuals = True

    def __init__(self, parts):
        self.parts = list(parts)
        self.chromosome_nodes = self.parts[0].chromosome_nodes
        if any(not np.array_equal(p.chromosome_nodes, self.chromosome_nodes) for p in self.parts):
            raise ValueError("the records of one search must share its chromosome")

    def __call__(self):
        return RecordsEvaluator([part() for part in self.parts])


class RecordsEvaluator:
    def __init__(self, evaluators):
        self.evaluators = evaluators

    def J(self, mask):
        return sum(e.J(mask) for e in self.evaluators)

    def residuals(self, mask):
        """(sum of N_t, k) residuals (C) of the records in turn, NaN where not scored."""
        return np.vstack([e.residuals(mask) for e in self.evaluators])

    def close(self):
        for e in self.evaluators:
            e.close()


class ModelFitness:
    """Factory of evaluators of the same J as `FmuFitness`, simulated by the direct model.

    Parameters
    ----------
    building : model.building.Building the case belongs to
    case, chromosome_nodes, objective, warmup_days : as for FmuFitness
    """

    keeps_residuals = True

    def __init__(self, building, case, chromosome_nodes, objective, warmup_days=2):
        self.building = building
        self.case = case
        self.chromosome_nodes = np.asarray(chromosome_nodes, dtype=int)
        self.objective = objective
        self.warmup_days = warmup_days

    def __call__(self):
        return ModelEvaluator(self)


class _Evaluator:
    """J (C2) of a mask over the spec's chromosome nodes; subclasses simulate the objective's air."""

    def __init__(self, spec):
        self.spec = spec
        self.measured = spec.objective.measured(spec.case)

    def J(self, mask):
        return self.spec.objective.J(self.measured, self.air(self._force(mask)))

    def residuals(self, mask):
        """(N_t, k) residuals (C) of the objective's air with the mask forced, NaN where not scored:
        what J sums, kept per step for the paired comparison of two forcings."""
        return self.measured - self.air(self._force(mask))

    def _force(self, mask):
        force = np.zeros(self.spec.case.measured.shape[1], dtype=bool)
        force[self.spec.chromosome_nodes[np.asarray(mask, dtype=bool)] - 1] = True
        return force

    def close(self):
        """Free what the evaluator holds (nothing for the direct model)."""


class FmuEvaluator(_Evaluator):
    def __init__(self, spec):
        super().__init__(spec)
        self.instance = FmuInstance(spec.fmu_path)
        self.runs = CaseRuns(spec.case, spec.warmup_days)  # what every forcing's run sets alike

    def air(self, force):
        """Objective air temperatures (C) at t_1..t_N with the `force` (N,) bool nodes forced."""
        return self.runs.simulate(self.instance, force, output_ids=self.spec.objective.air_nodes)

    def close(self):
        """Free the FMU instance and remove its extracted files."""
        self.instance.close()


class ModelEvaluator(_Evaluator):
    def __init__(self, spec):
        super().__init__(spec)
        self.network = assemble(spec.building)
        self.stepper = ImplicitEuler(self.network, spec.case.dt / spec.case.substeps)  # kept: its factors
        self.steady = ImplicitEuler(self.network, STEADY_STEP) if spec.case.steady_start else None
        self.history = (ImplicitEuler(self.network, history_block(spec.case.dt) * spec.case.dt)
                        if spec.case.history_steps else None)

    def air(self, force):
        """Objective air temperatures (C) at t_1..t_N with the `force` (N,) bool nodes forced."""
        case = self.spec.case
        T = simulate(self.spec.building, self.network, case.U, case.dt, case.measured, force=force,
                     warmup_days=self.spec.warmup_days, burn_in_steps=case.burn_in_steps, stepper=self.stepper,
                     steady_start=case.steady_start, steady_stepper=self.steady, substeps=case.substeps,
                     history_steps=case.history_steps, history_stepper=self.history,
                     outputs=np.array(self.spec.objective.air_nodes) - 1)
        return T
