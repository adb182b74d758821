"""The genetic operators of the paper's simple GA, as PyGAD callables.

Lauret et al. use the classic binary GA (Goldberg): fitness-proportionate (roulette wheel)
selection, one-point crossover applied to a mated pair with probability pc, and bit-flip
mutation of every gene with probability pm.  PyGAD's built-in operators differ in ways that
matter here: its crossover_probability is tested per parent rather than per pair (so crossover
happens almost always, whatever pc), and its "random" mutation over gene_space [0, 1] redraws
the value, which flips a bit with probability pm/2 only.  Hence these three small callables;
PyGAD still drives the loop, elitism and the seeded random generator they draw from
(ga.numpy_random_generator), which is what makes runs reproducible and resumable.
"""

from __future__ import annotations

import numpy as np


def roulette_selection(fitness, num_parents, ga):
    """Fitness-proportionate selection of the mating pool, f = 1/(1+J).

    If every chromosome is unfit (f = 0: all simulations failed), the wheel has no area;
    draw uniformly rather than stop the search.
    """
    fitness = np.asarray(fitness, dtype=float)
    total = fitness.sum()
    p = fitness / total if total > 0 else None
    idx = ga.numpy_random_generator.choice(len(fitness), size=num_parents, p=p)
    return ga.population[idx].copy(), idx


def one_point_crossover(parents, offspring_size, ga):
    """Pairs of the mating pool (in draw order) cross at one random cut with probability pc.

    A pair that does not cross passes on unchanged copies.  The cut lies strictly inside the
    chromosome so both children mix both parents.
    """
    rng = ga.numpy_random_generator
    n_offspring, n_genes = offspring_size
    offspring = np.empty(offspring_size, dtype=parents.dtype)
    for first in range(0, n_offspring, 2):
        a = parents[first % len(parents)]
        b = parents[(first + 1) % len(parents)]
        if n_genes >= 2 and rng.random() < ga.crossover_probability:
            cut = rng.randint(1, n_genes)
            a, b = np.concatenate([a[:cut], b[cut:]]), np.concatenate([b[:cut], a[cut:]])
        offspring[first] = a
        if first + 1 < n_offspring:
            offspring[first + 1] = b
    return offspring


def bit_flip_mutation(offspring, ga):
    """Every gene of every offspring flips independently with probability pm."""
    flips = ga.numpy_random_generator.random(offspring.shape) < ga.mutation_probability
    return np.where(flips, 1 - offspring, offspring).astype(offspring.dtype)
