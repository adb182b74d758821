"""The Morris screening of a chosen effect's parameters (report.json's `sensitivity`): how much
J moves with each over its range, and how much that depends on the others. The client's alone,
after a round's choice; a module apart from the calibration, which every worker imports."""
import numpy as np
from SALib.analyze import morris as morris_analyze
from SALib.sample import morris as morris_sample

from nodeforce.model.case import as_cases

MORRIS_TRAJECTORIES = 4


def sensitivity(candidate, cases, objective, seed=0):
    """Morris elementary effects of the parameters, over their bounds, on J of `cases` (a Case,
    or several records' calibration windows, their J summed).

    Returns {name: {"mu_star": C2, "sigma": C2}}: mu* ranks how much J moves with a parameter,
    sigma how much that depends on the others (interaction or non-linearity).
    """
    cases = as_cases(cases)
    measured = [objective.measured(case) for case in cases]
    problem = {"num_vars": len(candidate.parameters), "names": [p.name for p in candidate.parameters],
               "bounds": [list(b) for b in candidate.bounds]}
    X = morris_sample.sample(problem, MORRIS_TRAJECTORIES, num_levels=4, seed=seed)
    Y = np.array([sum(objective.J(m, candidate.nodes(case, objective.air_nodes, x)) for case, m in zip(cases, measured))
                  for x in X])
    analysis = morris_analyze.analyze(problem, X, Y, num_levels=4, seed=seed)
    return {name: {"mu_star": float(m), "sigma": float(s)}
            for name, m, s in zip(problem["names"], analysis["mu_star"], analysis["sigma"])}
