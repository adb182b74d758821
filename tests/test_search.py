"""The forcing search (ga/) on synthetic evaluators whose answer is known by construction.

Synthetic J(mask) = base + sum of the weights of the forced nodes (+ pair interactions): a
negative weight is a node whose forcing repairs the model (a node next to a wrong sub-model), a
positive one a node whose forcing only adds error.  Factories are module-level dataclasses so
they pickle into worker processes, as the FMU factory will.
"""

import itertools
import logging
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from nodeforce.ga import parsimony
from nodeforce.ga.search import search

NODES12 = [1, 3, 5, 7, 9, 11, 13, 15, 17, 19, 21, 22]  # ids are not positions


@dataclass(frozen=True)
class Synthetic:
    weights: tuple                 # J change when node i is forced
    pairs: tuple = ()              # (i, j, w): extra J change when both are forced
    base: float = 100.0
    fail_index: "int | None" = None   # forcing this node makes the simulation raise
    crash_mask: "tuple | None" = None  # this mask kills the worker process (a C-library crash)
    log_dir: "str | None" = None   # every mask the evaluators see is appended here

    def __call__(self):
        return SyntheticEvaluator(self)


class SyntheticEvaluator:
    def __init__(self, spec: Synthetic):
        self.spec = spec
        if spec.log_dir:
            with open(Path(spec.log_dir) / f"evaluators-{os.getpid()}.txt", "a") as f:
                f.write("built\n")

    def J(self, mask):
        spec = self.spec
        assert len(mask) == len(spec.weights) and all(isinstance(b, bool) for b in mask)
        if spec.log_dir:
            with open(Path(spec.log_dir) / f"masks-{os.getpid()}.txt", "a") as f:
                f.write("".join("1" if b else "0" for b in mask) + "\n")
        if spec.fail_index is not None and mask[spec.fail_index]:
            raise RuntimeError("solver diverged")
        if spec.crash_mask is not None and tuple(mask) == spec.crash_mask:
            os._exit(3)
        return (spec.base + sum(w for w, b in zip(spec.weights, mask) if b)
                + sum(w for i, j, w in spec.pairs if mask[i] and mask[j]))


def linear(k, gains, penalty=2.0, **kw):
    """Nodes in `gains` lower J by their gain when forced; every other node raises it."""
    return Synthetic(tuple(-gains.get(i, -penalty) for i in range(k)), **kw)


def brute_force(spec, k):
    masks = list(itertools.product((False, True), repeat=k))
    Js = [SyntheticEvaluator(spec).J(m) for m in masks]
    return min(zip(Js, [sum(m) for m in masks], masks))


def seen_masks(log_dir):
    return [line for f in Path(log_dir).glob("masks-*.txt") for line in f.read_text().split()]


def evaluators_built(log_dir):
    """Per process that built evaluators: how many it built."""
    return [len(f.read_text().split()) for f in Path(log_dir).glob("evaluators-*.txt")]


def without_time(result):
    return {**result, "search": {k: v for k, v in result["search"].items() if k != "seconds"}}


TWELVE = linear(12, {1: 40.0, 6: 25.0, 9: 15.0})
GA_BUDGET = dict(population=30, generations=60)  # 1800 evaluations < 2^12: the GA runs


def test_ga_finds_the_wrong_submodels():
    result = search(TWELVE, NODES12, workers=1, **GA_BUDGET)
    assert result["search"]["method"] == "ga"
    assert result["best_nodes"] == [3, 13, 19]
    assert result["J_best"] == pytest.approx(20.0)
    assert result["J_unforced"] == pytest.approx(100.0)
    assert result["ranked_nodes"] == [3, 13, 19]
    assert result["node_scores"]["3"] == pytest.approx(60.0)
    assert result["node_scores"]["1"] == pytest.approx(102.0)
    assert set(result["search"]) >= {"method", "population", "generations", "pc", "pm", "seed",
                                     "evaluations", "unique_evaluations", "seconds"}


def test_exhaustive_when_the_budget_covers_every_chromosome():
    rng = np.random.default_rng(7)
    k = 6
    pairs = tuple((i, j, float(w)) for (i, j), w in
                  zip(itertools.combinations(range(k), 2), rng.normal(0, 8, 15)))
    spec = Synthetic(tuple(rng.normal(0, 10, k)), pairs)
    result = search(spec, list(range(k)), population=8, generations=8, workers=1)  # 64 = 2^6
    J, _, mask = brute_force(spec, k)
    assert result["search"]["method"] == "exhaustive"
    assert result["search"]["unique_evaluations"] == 2 ** k
    assert result["search"]["J_min"] == pytest.approx(J)
    assert result["search"]["min_nodes"] == [i for i in range(k) if mask[i]]
    # one evaluation short of the budget: the GA runs instead
    assert search(spec, list(range(k)), population=9, generations=7,
                  workers=1)["search"]["method"] == "ga"


def test_cache_never_simulates_a_chromosome_twice(tmp_path):
    spec = linear(12, {1: 40.0, 6: 25.0, 9: 15.0}, log_dir=str(tmp_path))
    result = search(spec, NODES12, workers=1, **GA_BUDGET)
    seen = seen_masks(tmp_path)
    assert len(seen) == len(set(seen)) == result["search"]["unique_evaluations"]
    assert result["search"]["unique_evaluations"] < result["search"]["evaluations"]


def test_parsimony_drops_noise_level_nodes_and_keeps_real_ones():
    # node 0 repairs the model; node 2 lowers J by 0.5, below the noise (tolerance 1.34);
    # node 4 lowers it by 5, well above.
    spec = linear(6, {0: 50.0, 2: 0.5, 4: 5.0})
    noise = dict(noise_sigma=0.1, n_residuals=1000)
    assert parsimony.tolerance(100.0, **noise) == pytest.approx(3 * 0.01 * np.sqrt(2000))
    result = search(spec, list(range(6)), population=8, generations=8, workers=1, **noise)
    assert result["search"]["min_nodes"] == [0, 2, 4]
    assert result["best_nodes"] == [0, 4]
    assert result["J_best"] == pytest.approx(45.0)


def test_parsimony_without_noise_estimate_uses_the_relative_floor():
    spec = linear(6, {0: 50.0, 2: 0.5})  # 0.5 < 1 % of J_unforced = 1.0
    result = search(spec, list(range(6)), population=8, generations=8, workers=1)
    assert result["best_nodes"] == [0]


def test_nothing_helps_gives_no_nodes():
    spec = linear(6, {3: 0.2})  # a gain far below the noise, every other node harmful
    result = search(spec, list(range(6)), population=8, generations=8, workers=1,
                    noise_sigma=0.1, n_residuals=1000)
    assert result["search"]["min_nodes"] == [3]
    assert result["best_nodes"] == []
    assert result["J_best"] == result["J_unforced"]


def test_backward_elimination_beyond_exact_size():
    # 12 forced nodes > EXACT_MAX_NODES: the greedy path must peel off the 11 tiny ones.
    spec = Synthetic(tuple([-50.0] + [-0.01] * 11))
    best = (True,) * 12
    evaluator = spec()
    J_min = evaluator.J(best)
    kept = parsimony.smallest_subset(lambda ms: [evaluator.J(m) for m in ms], best, J_min + 1.0)
    assert kept == (True,) + (False,) * 11


def test_failed_simulations_score_unfit_and_the_run_goes_on(caplog):
    # forcing node index 4 would repair the most, but its simulation always fails
    spec = linear(12, {1: 60.0, 4: 80.0}, fail_index=4)
    with caplog.at_level(logging.WARNING, logger="nodeforce.ga"):
        result = search(spec, NODES12, workers=1, **GA_BUDGET)
    assert result["best_nodes"] == [3]
    assert result["node_scores"]["9"] is None
    assert 9 not in result["ranked_nodes"]
    assert any("simulation failed" in r.message and "solver diverged" in r.message
               for r in caplog.records)


def test_a_forcing_that_only_compensates_locates_nothing():
    # forcing node 2 lowers J by a fifth, well beyond the noise, but leaves most of the error:
    # the fault is where no forcing reaches (the paper's inside-convection case)
    spec = linear(6, {2: 20.0}, base=100.0)
    result = search(spec, [1, 2, 3, 4, 5, 6], workers=1, noise_sigma=0.05, n_residuals=400)
    assert result["search"]["min_nodes"] == [3]
    assert result["ranked_nodes"] == [3]
    assert result["best_nodes"] == []
    # the same gain, when it removes most of the error, locates node 3
    located = search(linear(6, {2: 90.0}, base=100.0), [1, 2, 3, 4, 5, 6], workers=1,
                     noise_sigma=0.05, n_residuals=400)
    assert located["best_nodes"] == [3]


def test_a_crashing_worker_only_loses_its_own_chromosome():
    # the best chromosome, nodes 1 and 3, kills its worker: the next best wins
    spec = linear(3, {0: 10.0, 2: 5.0}, penalty=20.0, crash_mask=(True, False, True))
    result = search(spec, [1, 2, 3], population=4, generations=2, workers=2)
    assert result["search"]["method"] == "exhaustive"
    assert result["search"]["min_nodes"] == [1]
    assert result["search"]["J_min"] == pytest.approx(90.0)
    assert result["node_scores"]["3"] == pytest.approx(95.0)
    assert result["search"]["unique_evaluations"] == 8


def test_same_seed_same_result():
    first = search(TWELVE, NODES12, workers=1, seed=3, **GA_BUDGET)
    again = search(TWELVE, NODES12, workers=1, seed=3, **GA_BUDGET)
    assert without_time(first) == without_time(again)


class Interrupt(Exception):
    pass


def stop_after(generation):
    def progress(g, total, J_min, unique):
        if g == generation:
            raise Interrupt
    return progress


@pytest.mark.parametrize("budget", [GA_BUDGET, dict(population=300, generations=20)],
                         ids=["ga", "exhaustive"])
def test_interrupted_run_resumes_to_the_uninterrupted_answer(tmp_path, budget):
    uninterrupted = search(TWELVE, NODES12, workers=1, **budget)
    spec = linear(12, {1: 40.0, 6: 25.0, 9: 15.0}, log_dir=str(tmp_path))
    path = tmp_path / "out" / "search.json"
    with pytest.raises(Interrupt):
        search(spec, NODES12, workers=1, checkpoint=path, progress=stop_after(7), **budget)
    resumed = search(spec, NODES12, workers=1, checkpoint=path, **budget)
    assert without_time(resumed) == without_time(uninterrupted)
    seen = seen_masks(tmp_path)  # the resumed run simulated nothing twice
    assert len(seen) == len(set(seen)) == resumed["search"]["unique_evaluations"]
    # a finished run's checkpoint answers a rerun without simulating anything
    rerun = search(spec, NODES12, workers=1, checkpoint=path, **budget)
    assert without_time(rerun) == without_time(uninterrupted)
    assert len(seen_masks(tmp_path)) == len(seen)


def test_checkpoint_of_other_arguments_is_not_resumed(tmp_path):
    path = tmp_path / "search.json"
    with pytest.raises(Interrupt):
        search(TWELVE, NODES12, workers=1, seed=0, checkpoint=path, progress=stop_after(5),
               **GA_BUDGET)
    other = search(TWELVE, NODES12, workers=1, seed=1, checkpoint=path, **GA_BUDGET)
    assert without_time(other) == without_time(search(TWELVE, NODES12, workers=1, seed=1,
                                                      **GA_BUDGET))


def test_two_worker_processes_give_the_same_result(tmp_path):
    serial = search(TWELVE, NODES12, workers=1, **GA_BUDGET)
    spec = linear(12, {1: 40.0, 6: 25.0, 9: 15.0}, log_dir=str(tmp_path))
    parallel = search(spec, NODES12, workers=2, **GA_BUDGET)
    assert without_time(parallel) == without_time(serial)
    assert evaluators_built(tmp_path) == [1, 1]  # one evaluator per worker process


def test_dask_cluster_gives_the_same_result(tmp_path):
    distributed = pytest.importorskip("distributed")
    budget = dict(population=20, generations=15)
    serial = search(TWELVE, NODES12, workers=1, **budget)
    spec = linear(12, {1: 40.0, 6: 25.0, 9: 15.0}, log_dir=str(tmp_path))
    with distributed.LocalCluster(n_workers=2, processes=True, threads_per_worker=1,
                                  dashboard_address=None) as cluster:
        on_dask = search(spec, NODES12, scheduler=cluster.scheduler_address, **budget)
    assert without_time(on_dask) == without_time(serial)
    assert evaluators_built(tmp_path) == [1, 1]  # one evaluator per Dask worker
