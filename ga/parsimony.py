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

First, does any forcing explain the residual? Forcing the node of a defective sub-model removes
most of the error: J falls towards what the noise alone gives, n*sigma^2. A forcing that only
compensates for a fault elsewhere (one in the air node's own equation, say, which no forcing
can reach) lowers J by a fraction. So the search has located something only when

    J_min - n sigma^2 <= EXPLAINED * (J_unforced - n sigma^2)

(EXPLAINED = 0.5: the best forcing removes at least half of the error above the noise);
otherwise best_nodes = [].

Rule: best_nodes = the smallest set S with J(S) <= J_min + tolerance, looked for among the
empty set, every single node (their scores are computed for the ranking anyway) and the subsets
of the best chromosome. Within the tolerance the sets cannot be told apart from the noise, so
among the smallest that fit, the one earliest in the chromosome order wins: the caller orders
the nodes by preference (nodes nearest the zone first, ga.locate). The empty set comes first, so
best_nodes = [] exactly when J_unforced - J_min <= tolerance: no significant reduction.
Subsets of the best chromosome are searched exhaustively, smallest first, when it forces at most
EXACT_MAX_NODES nodes; otherwise by backward elimination: repeatedly drop the node whose
removal raises J least, while the rule still holds.

Before the GA, the search runs a forward-backward pass under the same tolerance
(forward_backward): starting from no forcing, add the node that lowers J most while the fall
exceeds the tolerance; after each addition drop any node whose removal raises J by no more
than the tolerance (it no longer pays). It finds additive faults in about k simulations per
node kept; the GA then has to beat it, which it can only do through interactions between
sub-models, the paper's reason for a GA.
"""

from __future__ import annotations

import math
from itertools import combinations
from typing import Callable, Sequence

Z_NOISE = 3.0
EXPLAINED = 0.5
RELATIVE_FLOOR = 0.01
EXACT_MAX_NODES = 8


def tolerance(J_unforced: float, noise_sigma: "float | None", n_residuals: "int | None") -> float:
    """The change of J that is not significant (see the module docstring)."""
    floor = RELATIVE_FLOOR * J_unforced
    if noise_sigma is None:
        return floor
    return max(floor, Z_NOISE * noise_sigma ** 2 * math.sqrt(2 * n_residuals))


def explains(J_unforced: float, J_min: float, noise_sigma: "float | None", n_residuals: "int | None") -> bool:
    """Whether the best forcing removes enough of the residual to locate a fault (docstring above)."""
    J_noise = 0.0 if noise_sigma is None else n_residuals * noise_sigma ** 2
    return J_min - J_noise <= EXPLAINED * (J_unforced - J_noise)


def smallest_subset(J_many: Callable[[Sequence[tuple]], list], best: tuple, limit: float) -> tuple:
    """The smallest sub-mask of `best` whose J stays <= limit (J_min + tolerance).

    J_many scores a batch of masks (through the fitness cache, so a batch runs in parallel).
    """
    def mask(subset):
        chosen = set(subset)
        return tuple(i in chosen for i in range(len(best)))

    if J_many([mask(())])[0] <= limit:
        return mask(())
    singles = J_many([mask((i,)) for i in range(len(best))])
    fitting = [i for i, J in enumerate(singles) if J <= limit]
    if fitting:
        return mask((fitting[0],))
    members = [i for i, bit in enumerate(best) if bit]
    search = _smallest_first if len(members) <= EXACT_MAX_NODES else _backward_elimination
    return mask(search(J_many, mask, members, limit))


def _smallest_first(J_many, mask, members, limit):
    for size in range(2, len(members)):
        subsets = list(combinations(members, size))
        fits = [s for J, s in zip(J_many([mask(s) for s in subsets]), subsets) if J <= limit]
        if fits:
            return fits[0]  # combinations keep the caller's order: the preferred set first
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


def forward_backward(J_many: Callable[[Sequence[tuple]], list], k: int, tol: float) -> "tuple[tuple, float]":
    """Stepwise selection over k nodes judged against the noise; returns (mask, J).

    J_many scores a batch of masks (each step's candidates run in parallel). Ties go to the
    node earlier in the chromosome order, the caller's preference. A set already visited is
    never entered again, so the pass ends.
    """
    current = (False,) * k
    [J_current] = J_many([current])
    visited = {current}
    while True:
        grown = [current[:i] + (True,) + current[i + 1:] for i in range(k) if not current[i]]
        step = _best_unvisited(J_many, grown, visited)
        if step is None or J_current - step[0] <= tol:
            return current, J_current
        J_current, current = step
        visited.add(current)
        while sum(current) > 1:
            shrunk = [current[:i] + (False,) + current[i + 1:] for i in range(k) if current[i]]
            step = _best_unvisited(J_many, shrunk, visited)
            if step is None or step[0] - J_current > tol:
                break
            J_current, current = step
            visited.add(current)


def _best_unvisited(J_many, masks, visited):
    """(J, mask) of lowest J among the masks not yet visited (first in order on ties)."""
    fresh = [m for m in masks if m not in visited]
    if not fresh:
        return None
    Js = J_many(fresh)
    i = min(range(len(fresh)), key=Js.__getitem__)
    return Js[i], fresh[i]
