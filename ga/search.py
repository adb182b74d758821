"""Locate the wrong sub-models: search the forcing masks of lowest J (Lauret et al.).

A chromosome has one bit per measured node (the output air node excluded); bit i set = node i
forced to its measured temperature for the whole run.  Forcing a node cuts the model at that
node: if J (sum of squared residuals of indoor air temperature) drops, the error lies in the
sub-models the forced node isolates.  The fitness is f = 1/(1+J) (paper eq. 8).

search() runs the paper's simple GA through PyGAD (roulette selection, one-point crossover
with probability pc, bit-flip mutation with probability pm per gene, see ga.operators; plus
one elite carried to the next generation so the best chromosome is never lost), or, when the
GA's budget population*generations covers all 2^k chromosomes, simply scores them all: the
exact answer for no more work.  Every J goes through one cache, so a chromosome is simulated
at most once, whether asked for by the GA, the single-node scores or the parsimony step.

By default the GA starts from what the search computes anyway and stops once it has nothing
left to find (the paper's "convergence criterion", which it does not define):

- before the GA, the unforced and single-node scores and a forward-backward pass
  (ga.parsimony.forward_backward) are computed; the initial population holds the pass's
  result, the significant single nodes and their cumulative unions (at most half of it), the
  rest drawn at random.  The elite keeps the pass's result, so the GA can only beat it;
- the GA stops when its best J has not fallen by more than the noise tolerance
  (ga.parsimony.tolerance) for `patience` generations (PATIENCE, measured: README).

PAPER holds the paper's settings: 30 x 400, random initial population, no convergence
criterion; with them the search is the one of earlier releases, draw for draw.
"""

from __future__ import annotations

import math
import os
import sys
import time
from dataclasses import dataclass
from typing import Callable
from functools import partial
from itertools import product

import numpy as np
import pygad
from tqdm import tqdm

from nodeforce.ga import checkpoint as ckpt
from nodeforce.ga.evaluation import FitnessCache, log, open_backend
from nodeforce.ga.operators import bit_flip_mutation, one_point_crossover, roulette_selection
from nodeforce.ga.parsimony import (Paired, explains, forward_backward, noise_J, noise_tolerance, smallest_subset,
                                    tolerance)
from nodeforce.model.errors import InputError
from nodeforce.model.score import Yardstick

# Generations without a significant fall of the best J before the GA stops. Measured on the
# paper's verification cases (benchmarks/bench_search.py --cases, README): successive falls of
# the best J by more than the tolerance came at most 18 generations apart.
PATIENCE = 25
# The paper's search: its GA settings, a random initial population, no convergence criterion.
PAPER = dict(population=30, generations=400, pc=0.8, pm=0.03, patience=None, seeded=False)


def check_settings(population, generations, pc, pm, patience=None):
    """The GA's settings, the one place they are checked, where a `SearchSettings` is made:
    refused with the command-line option that sets each named (InputError), by the command
    before any work and for a caller of the API alike. `patience` None: no convergence criterion."""
    if population < 2:
        raise InputError("--population", population, "a population needs at least 2 chromosomes")
    if generations < 1:
        raise InputError("--generations", generations, "at least one generation")
    for option, p in (("--pc", pc), ("--pm", pm)):
        if not 0.0 <= p <= 1.0:
            raise InputError(option, p, "a probability, between 0 and 1")
    if patience is not None and patience < 1:
        raise InputError("--patience", patience, "at least one generation")


@dataclass(frozen=True)
class SearchSettings:
    """The forcing search's settings, checked once where they are made (`check_settings`, an
    InputError naming the command-line option): the seed of every random draw; the GA's
    population, generations, crossover and mutation probabilities `pc`, `pm` (the paper: 30,
    400, 0.8, 0.03); `patience` (stop once the best J has not fallen by more than the noise
    tolerance for this many generations; None: run every generation, the paper) and `seeded`
    (start from the single-node scores and a forward-backward pass; False: a random initial
    population, the paper; PAPER = both off). `ga.locate.locate` reads the rest: the FMUs it
    drives (`fmu_kind`, "auto": the standalone where it can run the building, `evaluator_kind`),
    the nodes it may force (`nodes`, None: every measured node but the objective's air and,
    unless `include_algebraic`, the algebraic radiant nodes), the `warmup_days` of every
    simulation, and `noise`, the air sensors' noise sd (C) where the user knows it (None:
    estimated from the air, `model.score.Noise`), which a diagnosis judges its choice by too."""
    seed: int = 0
    population: int = 30
    generations: int = 400
    fmu_kind: str = "auto"
    pc: float = 0.8
    pm: float = 0.03
    patience: int | None = PATIENCE
    seeded: bool = True
    nodes: tuple | None = None
    include_algebraic: bool = False
    warmup_days: float = 2
    noise: float | None = None

    def __post_init__(self):
        check_settings(self.population, self.generations, self.pc, self.pm, self.patience)
        if self.nodes is not None:
            object.__setattr__(self, "nodes", tuple(self.nodes))

    @classmethod
    def paper(cls, **settings):
        """The paper's search (PAPER), with any other setting given."""
        return cls(**{**PAPER, **settings})


@dataclass(frozen=True)
class Execution:
    """Where a command's work runs, checked where it is made: `workers` processes (None: every
    core; or a runner of `runtime.lifetime` or `runtime.cluster` a command has started, which its
    later stages use too), or the workers of the Dask scheduler at `scheduler` ("tcp://host:port");
    the FMUs of the model it runs and writes (`fmu_build.build.build_fmu`'s kinds, or "auto",
    `ga.locate.evaluator_kind`); and `progress`, called after every generation of a forcing search
    with (generation, total, best J, unique evaluations)."""
    workers: object = None
    scheduler: str | None = None
    fmu_kind: str = "python"
    progress: Callable | None = None

    def __post_init__(self):
        if isinstance(self.workers, int) and self.workers < 1:
            raise InputError("--workers", self.workers, "at least one worker process")


def search(factory, chromosome_nodes, settings=SearchSettings(), execution=Execution(), *, checkpoint=None,
           noise_sigma=None, n_residuals=None) -> dict:
    """Search the forcing of lowest J over `chromosome_nodes`; return the locate.json fields.

    factory: picklable callable; factory() -> evaluator with J(mask: tuple[bool, ...]) -> float,
        mask over chromosome_nodes in order, and optionally close(), called when the search
        ends (ga.evaluation).  Called once per worker.  J may raise: that chromosome is unfit
        (J = inf), the reason logged on logger "nodeforce.ga".
    settings: `SearchSettings`: the seed (same arguments and seed -> same answer), population,
        generations, pc, pm, patience and seeded; its other fields are `ga.locate.locate`'s.
    execution: `Execution`: its `workers`, processes evaluating in parallel (default
        os.cpu_count(); 1 = in this process), or where a command runs its tasks
        (`lifetime.InProcess`, `lifetime.Workers`, a `runtime.cluster.Cluster`), which its later
        stages use too; or its `scheduler`, a dask.distributed scheduler address
        ("tcp://host:port"), which replaces `workers`; and its `progress`.
    checkpoint: a file path; the state is written there after every generation, and a run
        started again with the same arguments resumes from it (other arguments: ignored).
        `execution.progress`: optional callable progress(generation, total, J_min,
        unique_evaluations), called after each generation (after the checkpoint is written).  A
        tqdm bar is shown as well when stderr is a terminal.
    noise_sigma, n_residuals: measurement-noise sd (C) and the number of residuals in J, used to
        judge which reductions of J are significant (ga.parsimony); None = relative floor only.

    Returns the locate.json fields it knows, J values as floats (None: the simulation failed):
      chromosome_nodes; J_unforced (no node forced);
      node_scores {str(id): J with only that node forced};
      ranked_nodes: the nodes whose forcing alone lowers J below J_unforced, lowest J first;
        nodes that do not help are left out; tied_nodes: the groups of ranked nodes whose
        scores the noise tolerance cannot separate (`ties`);
      best_nodes: the smallest set of nodes that keeps the best chromosome's reduction of J
        (ga.parsimony), [] when no reduction is significant; J_best: J with best_nodes forced;
      search: {method "ga" | "exhaustive", population, generations, pc, pm, seed, patience,
        seeded, evaluations (J values the search asked for, cache hits included),
        unique_evaluations (simulations run), seconds, stopped ("converged": by the patience
        rule; "generations": every generation ran, or every batch of an exhaustive search),
        stopped_at (the generation it stopped at), J_min and min_nodes (the lowest J found and
        its chromosome; parsimony starts from `parsimonious_best`), tolerance (the change of J deemed noise),
        explains (whether the best forcing removes enough of J above the noise to locate a
        fault, ga.parsimony.explains), and when
        seeded stepwise_nodes and J_stepwise (the forward-backward pass's result)}.
    """
    started = time.monotonic()
    nodes = list(chromosome_nodes)
    _check_arguments(nodes, noise_sigma, n_residuals)
    population, generations, pc, pm, seed = settings.population, settings.generations, settings.pc, settings.pm, settings.seed
    patience, seeded, progress = settings.patience, settings.seeded, execution.progress
    workers, scheduler = execution.workers, execution.scheduler
    k = len(nodes)
    exhaustive = 2 ** k <= population * generations
    settings = dict(method="exhaustive" if exhaustive else "ga", population=population,
                    generations=generations, pc=pc, pm=pm, seed=seed, patience=patience,
                    seeded=seeded)
    key = ckpt.run_key(factory, nodes, **settings) if checkpoint else None
    state = ckpt.load(checkpoint, key) if checkpoint else None

    with open_backend(factory, workers or os.cpu_count(), scheduler) as backend:
        cache = FitnessCache(backend, ckpt.decode_cache(state["cache"]) if state else None, nodes)
        if state:
            cache.requests = state["requests"]
            log.info("resuming from %s at generation %d", checkpoint, state["generation"])
        total = math.ceil(2 ** k / population) if exhaustive else generations
        steps = _Steps(total, state["generation"] if state else 0, cache, checkpoint, key,
                       progress, settings["method"])
        extra = {}
        try:
            if exhaustive:
                _enumerate(cache, k, population, steps)
                stopped = "generations"
            else:
                # A resumed run repeats the steps before the GA from the cache, uncounted.
                J_many = partial(cache.J_many, count=state is None)
                start = _start(J_many, k, seeded, patience, noise_sigma, n_residuals)
                stop = Convergence(patience, start.tolerance,
                                   **(state["convergence"] if state else {"J_ref": start.J}))
                initial = (_seeded_population(start, population, k, seed)
                           if seeded and not state else None)
                stopped = _evolve(cache, k, population, pc, pm, seed, state, steps, stop, initial)
                if seeded:
                    extra = dict(stepwise_nodes=cache.describe(start.mask), J_stepwise=_json(start.J))
        finally:
            steps.close()
        search_requests = cache.requests
        answer = _answer(cache, nodes, noise_sigma, n_residuals, factory)
        if checkpoint:
            # Keep the final scores too, so a rerun is instant; the counter stays at the end of
            # the search so the rerun counts the final steps exactly once, like this run.
            steps.save(steps.done, requests=search_requests)
    answer["search"].update(settings, evaluations=cache.requests, unique_evaluations=cache.unique,
                            seconds=round(time.monotonic() - started, 3), stopped=stopped,
                            stopped_at=steps.done, **extra)
    return answer


def _check_arguments(nodes, noise_sigma, n_residuals):
    if len(set(map(str, nodes))) != len(nodes):
        raise ValueError(f"chromosome nodes must be distinct: {nodes}")
    if noise_sigma is not None and not n_residuals:
        raise ValueError("noise_sigma needs n_residuals, the number of residuals in J")


class _Steps:
    """After each generation: write the checkpoint, then move the bar and call `progress`."""

    def __init__(self, total, done, cache, path, key, progress, method):
        self.total, self.done = total, done
        self._cache, self._path, self._key, self._progress = cache, path, key, progress
        self._extra = {}
        self._bar = tqdm(total=total, initial=done, desc=f"nodeforce {method}", unit="gen",
                         disable=not sys.stderr.isatty())

    def save(self, generation, requests=None):
        ckpt.save(self._path, self._key, {
            "generation": generation, "cache": ckpt.encode_cache(self._cache.J_of),
            "requests": self._cache.requests if requests is None else requests, **self._extra})

    def step(self, generation, **extra):
        """extra: what a resumed run needs besides the cache (GA population, generators)."""
        self.done = generation
        self._extra = extra
        if self._path:
            self.save(generation)
        J_min = self._cache.J_of[self._cache.best()]
        self._bar.update(generation - self._bar.n)
        self._bar.set_postfix(best_J=f"{J_min:.4g}", unique=self._cache.unique)
        if self._progress:
            self._progress(generation, self.total, J_min, self._cache.unique)

    def close(self):
        self._bar.close()


def _enumerate(cache, k, population, steps):
    """Exhaustive mode: score all 2^k masks, `population` at a time (one 'generation')."""
    masks = list(product((False, True), repeat=k))
    for g in range(steps.done, steps.total):
        cache.J_many(masks[g * population:(g + 1) * population])
        steps.step(g + 1)


class Convergence:
    """The stopping rule: the best J has not fallen by more than `tol` for `patience` generations.

    J_ref is the best J at the last significant fall and `last` its generation (0: before the
    GA's first generation, J_ref the best J known then).  patience None: never converged.
    """

    def __init__(self, patience, tol, J_ref=math.inf, last=0):
        self.patience, self.tol = patience, tol
        self.J_ref = math.inf if J_ref is None else J_ref
        self.last = last

    def update(self, generation, J_min):
        if J_min < self.J_ref - self.tol:
            self.J_ref, self.last = J_min, generation

    def converged(self, generation) -> bool:
        return self.patience is not None and generation - self.last >= self.patience

    def state(self) -> dict:
        return {"J_ref": _json(self.J_ref), "last": self.last}


@dataclass(frozen=True)
class _Start:
    """What is known before the GA: the scores it is seeded from and the noise tolerance."""
    J_unforced: float
    J_single: list
    tolerance: float
    mask: tuple   # the forward-backward pass's result
    J: float      # its J (inf when nothing was computed: the paper's search)


def _start(J_many, k, seeded, patience, noise_sigma, n_residuals) -> _Start:
    """The unforced and single-node scores (the tolerance needs J_unforced) and, when seeded,
    the forward-backward pass; nothing for the paper's search, which starts from chance."""
    unforced = (False,) * k
    if not seeded and patience is None:
        return _Start(math.inf, [], 0.0, unforced, math.inf)
    J_unforced, *J_single = J_many([unforced] + _singles(k))
    tol = tolerance(J_unforced, noise_sigma, n_residuals)
    mask, J = forward_backward(J_many, k, tol) if seeded else (unforced, math.inf)
    return _Start(J_unforced, J_single, tol, mask, J)


def _singles(k):
    return [tuple(i == j for j in range(k)) for i in range(k)]


def _seeded_population(start, population, k, seed):
    """Initial population: the pass's result, then the significant single nodes, best first,
    each followed by the union of it and the better ones; at most half the population, so the
    random rest keeps the GA free to find interactions the single scores do not show."""
    helpful = [i for i in rank(start.J_single, start.J_unforced)
               if start.J_single[i] < start.J_unforced - start.tolerance]
    seeds = [start.mask]
    for m, i in enumerate(helpful):
        seeds.append(_singles(k)[i])
        seeds.append(tuple(j in helpful[:m + 1] for j in range(k)))
    seeds = list(dict.fromkeys(seeds))[:population // 2]
    random_rows = np.random.default_rng(seed).integers(0, 2, (population - len(seeds), k))
    return np.vstack([np.array(seeds, dtype=int).reshape(-1, k), random_rows])


def _evolve(cache, k, population, pc, pm, seed, state, steps, stop, initial):
    """The GA, driven by PyGAD; resumes from `state` (a checkpoint) when given.

    Returns why it stopped: "converged" (the `stop` rule) or "generations".
    """
    def why():
        return "converged" if stop.converged(steps.done) else "generations"

    if steps.done == steps.total or stop.converged(steps.done):
        return why()

    def fitness(ga, solutions, indices):
        # One call per generation (fitness_batch_size = population): the uncached chromosomes
        # of the generation go to the workers together.  Counted per generation instead (below)
        # because PyGAD itself skips the elite it already knows.
        return [1.0 / (1.0 + J) for J in cache.J_many([tuple(s) for s in solutions], count=False)]

    def on_generation(ga):
        cache.requests += population
        g = ga.generations_completed
        stop.update(g, cache.J_of[cache.best()])
        steps.step(g, population=ga.population.tolist(), rng=ckpt.rng_states(ga),
                   convergence=stop.state())
        return "stop" if stop.converged(g) else None

    if state:
        shape = dict(initial_population=state["population"])
    elif initial is not None:
        shape = dict(initial_population=initial)
    else:
        shape = dict(sol_per_pop=population, num_genes=k)
    ga = pygad.GA(num_generations=steps.total - steps.done, num_parents_mating=population,
                  fitness_func=fitness, fitness_batch_size=population, **shape,
                  gene_type=int, gene_space=[0, 1], parent_selection_type=roulette_selection,
                  keep_elitism=1, crossover_type=one_point_crossover, crossover_probability=pc,
                  mutation_type=bit_flip_mutation, mutation_probability=pm,
                  on_generation=on_generation, random_seed=seed, suppress_warnings=True,
                  logger=log.getChild("pygad"))
    if state:
        # Continue exactly where the checkpoint stopped: same generators, same generation count.
        ckpt.restore_rng_states(ga, state["rng"])
        ga.generations_completed = steps.done
    else:
        cache.requests += population  # the initial population, scored at the start of run()
    ga.run()
    return why()


def _answer(cache, nodes, noise_sigma, n_residuals, factory=None) -> dict:
    """The locate.json fields: unforced and single-node scores, best chromosome, best_nodes.
    Sets of one size are told apart by the paired test on their residuals when the factory's
    evaluators give them (`keeps_residuals`), else by the noise of one J (ga.parsimony)."""
    k = len(nodes)
    unforced = (False,) * k
    J_unforced, *J_single = cache.J_many([unforced] + _singles(k))
    tol = tolerance(J_unforced, noise_sigma, n_residuals)
    best = cache.best()
    J_min = cache.J_of[best]
    explained = explains(J_unforced, J_min, noise_sigma, n_residuals)
    if explained:
        start = parsimonious_best(cache.J_of, tol)
        paired = (Paired(factory, cache.J_many, Yardstick().rounding(J_unforced))
                  if getattr(factory, "keeps_residuals", False) else None)
        try:
            chosen = smallest_subset(cache.J_many, start, cache.J_of[start] + tol,
                                     noise_tolerance(noise_sigma, n_residuals), worse=paired.worse if paired else None)
        finally:
            if paired:
                paired.close()
    else:
        chosen = unforced
    return {
        "chromosome_nodes": nodes,
        "J_unforced": _json(J_unforced),
        "best_nodes": cache.describe(chosen),
        "J_best": _json(cache.J_of[chosen]),
        "node_scores": {str(n): _json(J) for n, J in zip(nodes, J_single)},
        "ranked_nodes": [nodes[i] for i in rank(J_single, J_unforced)],
        "tied_nodes": [[nodes[i] for i in group] for group in ties(J_single, J_unforced, tol)],
        "search": {"J_min": _json(J_min), "min_nodes": cache.describe(best),
                   "tolerance": _json(tol), "explains": explained,
                   "J_noise": _json(noise_J(noise_sigma, n_residuals))},
    }


def parsimonious_best(J_of, tol):
    """The scored mask of lowest J + tol x (nodes forced), whose subsets parsimony searches within
    the tolerance of its J: every node forced must lower J by more than the tolerance, the
    forward-backward pass's rule. With a hundred genes the GA otherwise
    gathers dozens of nodes that each lower J by less than the noise (fitting the noise and the
    start's transient), and their sum sets a J_min no small set reaches (benchmarks/bench_scale.py:
    the full office's three faults came back as 16 nodes, after 2,600 simulations of parsimony).
    Ties go to fewer forced nodes, then mask order."""
    return min(J_of, key=lambda m: (J_of[m] + tol * sum(m), sum(m), m))


def rank(J_single, J_unforced):
    """Indices of the nodes whose forcing alone lowers J, lowest J first (the order of their
    scores, whatever the noise can separate: `ties` says which it cannot)."""
    return sorted((i for i, J in enumerate(J_single) if J < J_unforced), key=lambda i: (J_single[i], i))


def ties(J_single, J_unforced, tol):
    """The groups (indices, lowest J first) of ranked nodes whose single scores the noise cannot
    separate: each group the nodes within `tol` of its first; only groups of two or more."""
    groups, group = [], []
    for i in rank(J_single, J_unforced):
        if group and J_single[i] <= J_single[group[0]] + tol:
            group.append(i)
        else:
            groups.append(group)
            group = [i]
    return [g for g in groups + [group] if len(g) > 1]


def _json(J: float) -> "float | None":
    """None for a failed simulation (inf), so the result is plain JSON."""
    return J if math.isfinite(J) else None
