"""best_nodes: the smallest part of the best chromosome that keeps its reduction of J.

The GA returns the chromosome of lowest J, but a node forced there may lower J only by chance
(noise in the measurements) or not at all (a gene that drifted in and did no harm).  Lauret et
al. read the located sub-models off the forced nodes, so we keep only the nodes the reduction
needs, judged against the measurement noise:

    tolerance = max(Z_NOISE * sigma^2 * sqrt(2 n),  RELATIVE_FLOOR * J_unforced)

With n residuals of independent noise of sd sigma, J of pure noise (sigma^2 times a chi-square
with n degrees of freedom) has sd sigma^2 * sqrt(2 n): a change of J smaller than Z_NOISE such
sds could be noise alone.  The relative floor keeps a noise-free (or unknown-noise: sigma None)
case from counting any tiny gain as real.

Rule: best_nodes = the smallest subset S of the best chromosome with
J(S) <= J_min + tolerance (ties: lowest J, then node order).  The empty subset comes first,
so best_nodes = [] exactly when J_unforced - J_min <= tolerance: no significant reduction.
Subsets are searched exhaustively, smallest first, when the best chromosome forces at most
EXACT_MAX_NODES nodes; otherwise by backward elimination: repeatedly drop the node whose
removal raises J least, while the rule still holds.
"""

from __future__ import annotations

import math
from itertools import combinations
from typing import Callable, Sequence

Z_NOISE = 3.0
RELATIVE_FLOOR = 0.01
EXACT_MAX_NODES = 8


def tolerance(J_unforced: float, noise_sigma: "float | None", n_residuals: "int | None") -> float:
    """The change of J that is not significant (see the module docstring)."""
    floor = RELATIVE_FLOOR * J_unforced
    if noise_sigma is None:
        return floor
    return max(floor, Z_NOISE * noise_sigma ** 2 * math.sqrt(2 * n_residuals))


def smallest_subset(J_many: Callable[[Sequence[tuple]], list], best: tuple, limit: float) -> tuple:
    """The smallest sub-mask of `best` whose J stays <= limit (J_min + tolerance).

    J_many scores a batch of masks (through the fitness cache, so a batch runs in parallel).
    """
    def mask(subset):
        chosen = set(subset)
        return tuple(i in chosen for i in range(len(best)))

    if J_many([mask(())])[0] <= limit:
        return mask(())
    members = [i for i, bit in enumerate(best) if bit]
    search = _smallest_first if len(members) <= EXACT_MAX_NODES else _backward_elimination
    return mask(search(J_many, mask, members, limit))


def _smallest_first(J_many, mask, members, limit):
    for size in range(1, len(members)):
        subsets = list(combinations(members, size))
        fits = [(J, s) for J, s in zip(J_many([mask(s) for s in subsets]), subsets) if J <= limit]
        if fits:
            return min(fits, key=lambda fit: fit[0])[1]  # lowest J; ties: first in node order
    return members


def _backward_elimination(J_many, mask, members, limit):
    kept = members
    while len(kept) > 1:
        candidates = [[n for n in kept if n != drop] for drop in kept]
        J, i = min((J, i) for i, J in enumerate(J_many([mask(c) for c in candidates])))
        if J > limit:
            break
        kept = candidates[i]
    return kept
