"""best_nodes: the smallest set of forced nodes that keeps the best chromosome's reduction of J.

The GA returns the chromosome of lowest J, but a node forced there may lower J only by chance
(noise in the measurements) or not at all (a gene that drifted in and did no harm).  Lauret et
al. read the located sub-models off the forced nodes, so we keep only the nodes the reduction
needs, judged against the measurement noise by the yardstick the diagnosis' choice reads too
(`model.score.Yardstick`):

    tolerance = max(noise_sds * sigma^2 * sqrt(2 n),  least_fall_share * J_unforced)

With n residuals of independent noise of sd sigma, J of pure noise (sigma^2 times a chi-square
with n degrees of freedom) has sd sigma^2 * sqrt(2 n): a change of J smaller than noise_sds such
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
empty set, every set of at most EXACT_ANY nodes of the chromosome, and the subsets of the best
chromosome. A larger set must buy more than the noise of one J: that is the size of a fall
worth a sub-model. Among the smallest sets that fit, the one of lowest J wins, except where the
data cannot tell a set from it, and among those the one earliest in the chromosome order wins:
the caller orders the nodes by preference (nodes nearest the zone first, ga.locate). Whether
two forcings can be told apart is a paired question: both are scored on the same steps of the
same record, so they share its noise, and the difference of their J is far better determined
than either J. The residuals of the two forcings are recomputed (`Paired`: a few simulations,
only for the finalists) and their difference of J judged against its HAC standard deviation
(`model.significance.worse`, a Diebold-Mariano-type test allowing for the residuals'
correlation in time). Where the evaluator keeps no residuals, the noise of one J (noise_tolerance) is the band instead. So the inside surface of a wrong roof wins over the
layer behind it (their residuals differ by noise), but a wall that merely compensates a wrong
floor or door does not win over it because it comes first: its J is measurably worse on the
same steps, even when the gap is inside the noise band of one J. With noisy sensors on every
node the test also sees how much of a forced sensor's noise reaches the air: forcing the node
behind a faulty wall's inside surface may then fit measurably better than the surface itself,
and is named instead; both locate the same component. Sets of up to EXACT_ANY nodes are searched over the whole chromosome, so
the answer for one or two faults does not depend on the path the search took (above
ALL_PAIRS_UP_TO genes, pairs among the PAIR_POOL single nodes that lower J most, beyond the
noise: a building's 100 sensors make 4,950 pairs). The empty set
comes first, so best_nodes = [] exactly when J_unforced - J_min <= tolerance: no significant
reduction. Larger subsets of the best chromosome are searched exhaustively, smallest first,
when it forces at most EXACT_MAX_NODES nodes; otherwise by backward elimination: repeatedly
drop the node whose removal raises J least, while the rule still holds.

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

from nodeforce.model import significance
from nodeforce.model.score import Yardstick, removed

EXPLAINED = 0.5
EXACT_MAX_NODES = 8
EXACT_ANY = 2
# Above this many genes, pairs are not all scored (100 genes make 4,950 pairs, most of a search's
# budget): only pairs among the PAIR_POOL single nodes that lower J most, by more than the noise
# alone (larger sets come from the best chromosome). Measured in benchmarks/bench_scale.py.
ALL_PAIRS_UP_TO = 25
PAIR_POOL = 10


def tolerance(J_unforced: float, noise_sigma: "float | None", n_residuals: "int | None",
              yardstick: Yardstick = Yardstick()) -> float:
    """The change of J (C2) that is not significant (see the module docstring):
    `Yardstick.least_fall` of J_unforced."""
    return yardstick.least_fall(J_unforced, noise_sigma, n_residuals)


def noise_tolerance(noise_sigma: "float | None", n_residuals: "int | None",
                    yardstick: Yardstick = Yardstick()) -> float:
    """The change of J (C2) measurement noise of sd noise_sigma (C) alone can make; 0 if unknown."""
    return yardstick.noise_change(noise_sigma, n_residuals)


def noise_J(noise_sigma: "float | None", n_residuals: "int | None", yardstick: Yardstick = Yardstick()) -> float:
    """J (C2) of the noise alone, n sigma^2; 0 if the noise is unknown."""
    return yardstick.noise_J(noise_sigma, n_residuals)


def explains(J_unforced: float, J_min: float, noise_sigma: "float | None", n_residuals: "int | None") -> bool:
    """Whether the best forcing removes enough of the residual to locate a fault (docstring above)."""
    return removed(J_unforced, J_min, noise_J(noise_sigma, n_residuals)) >= 1 - EXPLAINED


def smallest_subset(J_many: Callable[[Sequence[tuple]], list], best: tuple, limit: float,
                    noise_tol: float = 0.0, worse: "Callable[[tuple, tuple], bool] | None" = None) -> tuple:
    """The smallest mask whose J stays <= limit (J_min + tolerance), by the rule above.

    J_many scores a batch of masks (through the fitness cache, so a batch runs in parallel);
    worse(a, b) says whether the data show mask a fitting worse than mask b (`Paired.worse`);
    without it, noise_tol (C2, the noise_tolerance) is what sets of one size must differ by to
    be told apart.
    """
    if worse is None:
        def worse(a, b):
            return J_many([a])[0] > J_many([b])[0] + noise_tol

    def mask(subset):
        chosen = set(subset)
        return tuple(i in chosen for i in range(len(best)))

    [J_none] = J_many([mask(())])
    if J_none <= limit:
        return mask(())
    members = [i for i, bit in enumerate(best) if bit]
    pool = list(range(len(best)))
    for size in range(1, EXACT_ANY + 1):
        chosen = _preferred(J_many, mask, list(combinations(pool, size)), limit, worse)
        if chosen is not None:
            return mask(chosen)
        if size == 1 and len(best) > ALL_PAIRS_UP_TO:
            J_single = J_many([mask((i,)) for i in pool])
            lowering = sorted((J, i) for i, J in enumerate(J_single) if J < J_none - noise_tol)
            pool = sorted(i for _, i in lowering[:PAIR_POOL])
    if len(members) <= EXACT_MAX_NODES:
        return mask(_smallest_first(J_many, mask, members, limit, worse))
    return mask(_backward_elimination(J_many, mask, members, limit))


def _preferred(J_many, mask, subsets, limit, worse):
    """Of the subsets (in preference order) whose J <= limit, the first the data do not show
    fitting worse than the lowest; None if none fits."""
    fits = [(J, s) for J, s in zip(J_many([mask(s) for s in subsets]), subsets) if J <= limit]
    if not fits:
        return None
    lowest = min(fits, key=lambda fit: fit[0])[1]
    return next(s for _, s in fits if s == lowest or not worse(mask(s), mask(lowest)))


def _smallest_first(J_many, mask, members, limit, worse):
    for size in range(EXACT_ANY + 1, len(members)):
        chosen = _preferred(J_many, mask, list(combinations(members, size)), limit, worse)
        if chosen is not None:
            return chosen
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


class Paired:
    """The paired comparison of two forcings (`worse`), on residuals recomputed by one evaluator
    of `factory` built in this process when first needed: the search's cache keeps only J, and
    only the few finalists of the parsimony rule need their series. Close it when done.

    factory: a fitness factory whose evaluators have residuals(mask) (`keeps_residuals`, ga.fitness).
    J_many, floor: the search's scores and the difference of J (C2) that is rounding, whatever
        the test says (`Yardstick.rounding` of J_unforced): on a noise-free record two forcings that both
        cut a fault off differ by nothing else.
    """

    def __init__(self, factory, J_many=None, floor=0.0):
        self._factory, self._evaluator, self._kept = factory, None, {}
        self._J_many, self._floor = J_many, floor

    def residuals(self, mask):
        if mask not in self._kept:
            if self._evaluator is None:
                self._evaluator = self._factory()
            self._kept[mask] = self._evaluator.residuals(mask)
        return self._kept[mask]

    def worse(self, a, b) -> bool:
        """Whether forcing mask a fits the record measurably worse than mask b."""
        if self._J_many is not None:
            J_a, J_b = self._J_many([a, b])
            if J_a - J_b <= self._floor:
                return False
        return significance.worse(self.residuals(a), self.residuals(b))

    def close(self):
        if self._evaluator is not None:
            close = getattr(self._evaluator, "close", None)
            if close:
                close()
        self._evaluator, self._kept = None, {}


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
