"""A forcing search of your own: PyGAD chooses which nodes to force, FMPy runs the building's FMU.

nodeforce's own search (`nodeforce locate`) has its rules; this script is what a user writes to
try others. Each chromosome has one bit per node the search may force; its cost is J, the sum
of squared residuals of the measured indoor air with those nodes forced to their measurements,
plus a penalty per forced node, so that a forcing must earn each node it adds. The FMU is
written and instantiated once; each chromosome resets and re-runs it.

At the end it prints the best forcing and checks it against `nodeforce locate`'s on the same
case: both must force the same sub-models (components, or zones' air). Exit status 0 when they
agree, 1 when they do not.

    python examples/driver.py                      # the demo's test cell and measurements
    python examples/driver.py --population 6 --generations 4 --penalty 1 --seed 3
"""
import argparse
import sys
import tempfile
from pathlib import Path

import pygad

import nodeforce

DATA = Path(__file__).resolve().parents[1] / "model" / "data"


def arguments(argv):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--building", default=DATA / "testcell_miami.json")
    p.add_argument("--weather", default=DATA / "miami_tmy2.csv")
    p.add_argument("--measurements", default=DATA / "demo_measurements.csv")
    p.add_argument("--burn-in-days", type=float, default=1.0)
    p.add_argument("--population", type=int, default=10)
    p.add_argument("--generations", type=int, default=20)
    p.add_argument("--pc", type=float, default=0.8, help="crossover probability")
    p.add_argument("--pm", type=float, default=0.1, help="mutation probability per gene")
    p.add_argument("--penalty", type=float, default=0.5, help="C2 added to J per forced node")
    p.add_argument("--seed", type=int, default=1)
    return p.parse_args(argv)


def sub_models(building, nodes):
    """The components, and the zones' air, that the forced `nodes` belong to."""
    nodes = set(nodes)
    return ({c.name for c in building.components if nodes & set(c.node_ids)}
            | {f"{z.name} air" for z in building.zones if z.air_node in nodes})


def main(argv=None):
    args = arguments(argv)
    building = nodeforce.read_building(args.building)
    case = nodeforce.measured_case(building, nodeforce.read_weather(args.weather),
                                   nodeforce.read_measurements(args.measurements), args.burn_in_days)
    air = nodeforce.objective(building)
    genes = nodeforce.forcing_candidates(building, case, air)
    names = building.node_names()
    print(f"{building.name}: {len(genes)} nodes the search may force: {genes}")

    def forced(solution):
        return [node for node, bit in zip(genes, solution) if bit]

    with tempfile.TemporaryDirectory() as tmp, \
            nodeforce.open_fmu(nodeforce.write_fmu(building, Path(tmp) / "model.fmu")) as fmu:
        J = {}  # each forcing simulated once

        def cost(solution):
            nodes = tuple(forced(solution))
            if nodes not in J:
                J[nodes] = nodeforce.score_forcing(fmu, case, nodes, air)
            return J[nodes] + args.penalty * len(nodes)

        def fitness(ga, solution, index):
            return -cost(solution)  # PyGAD maximises

        def on_generation(ga):
            best, value, _ = ga.best_solution(pop_fitness=ga.last_generation_fitness)
            print(f"generation {ga.generations_completed:3d}: best {forced(best)}, cost {-value:.3f} C2, "
                  f"{len(J)} forcings simulated")

        ga = pygad.GA(num_generations=args.generations, sol_per_pop=args.population,
                      num_parents_mating=max(2, args.population // 2), num_genes=len(genes),
                      gene_type=int, gene_space=[0, 1], fitness_func=fitness,
                      parent_selection_type="rws", keep_elitism=1,
                      crossover_type="single_point", crossover_probability=args.pc,
                      mutation_type="random", mutation_probability=args.pm,
                      on_generation=on_generation, random_seed=args.seed, suppress_warnings=True)
        ga.run()
        best, value, _ = ga.best_solution(pop_fitness=ga.last_generation_fitness)
        mine = forced(best)
        J_unforced = cost([0] * len(genes))  # no node forced: no penalty

    print(f"best forcing: {', '.join(f'{i} ({names[i]})' for i in mine) or 'none'}: "
          f"J = {J[tuple(mine)]:.3f} C2 (unforced {J_unforced:.3f}), cost {-value:.3f} C2")
    located = nodeforce.locate(building, case, objective=air, search=nodeforce.SearchSettings(seed=args.seed),
                               execution=nodeforce.Execution(workers=1))
    print(f"nodeforce locate: {located.best_nodes or 'none'}: J = {located.J_best:.3f} C2")
    ours, theirs = sub_models(building, mine), sub_models(building, located.best_nodes)
    if ours == theirs:
        print(f"agree: both force {', '.join(sorted(ours)) or 'nothing'}")
        return 0
    print(f"disagree: this search forces {sorted(ours)}, nodeforce locate {sorted(theirs)}")
    return 1


if __name__ == "__main__":
    sys.exit(main())
