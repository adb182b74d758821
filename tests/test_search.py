"""The forcing search (ga/) on synthetic evaluators whose answer is known by construction.

Synthetic J(mask) = base + sum of the weights of the forced nodes (+ pair interactions): a
negative weight is a node whose forcing repairs the model (a node next to a wrong sub-model), a
positive one a node whose forcing only adds error.  Factories are module-level dataclasses so
they pickle into worker processes, as the FMU factory will.
"""

import itertools
import logging
import os
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from nodeforce.runtime import lifetime
from nodeforce.fmu_build.build import build_fmu
from nodeforce.ga import parsimony
from nodeforce.model.score import Objective
from nodeforce.ga.fitness import FmuFitness
from nodeforce.ga.search import PAPER, Execution, SearchSettings, search
from nodeforce.model.case import prepare_case
from nodeforce.model.synth import pseudo_measurements
from tests.conftest import SENSORS, record_times

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

    def close(self):
        if self.spec.log_dir:
            with open(Path(self.spec.log_dir) / f"evaluators-{os.getpid()}.txt", "a") as f:
                f.write("closed\n")


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
    return [f.read_text().split().count("built") for f in Path(log_dir).glob("evaluators-*.txt")]


def evaluator_logs(log_dir):
    """{pid: what its evaluators said, "built" and "closed", in order}."""
    return {int(f.stem.split("-")[1]): f.read_text().split() for f in Path(log_dir).glob("evaluators-*.txt")}


def without_time(result):
    return {**result, "search": {k: v for k, v in result["search"].items() if k != "seconds"}}


TWELVE = linear(12, {1: 40.0, 6: 25.0, 9: 15.0})
GA_BUDGET = dict(population=30, generations=60)  # 1800 evaluations < 2^12: the GA runs
LONG_GA = dict(population=30, generations=130)  # 3900 < 2^12, more than the searches need


def test_ga_finds_the_wrong_submodels():
    result = search(TWELVE, NODES12, SearchSettings(**GA_BUDGET), execution=Execution(workers=1))
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
    result = search(spec, list(range(k)), SearchSettings(population=8, generations=8),
                    execution=Execution(workers=1))  # 64 = 2^6
    J, _, mask = brute_force(spec, k)
    assert result["search"]["method"] == "exhaustive"
    assert result["search"]["unique_evaluations"] == 2 ** k
    assert result["search"]["J_min"] == pytest.approx(J)
    assert result["search"]["min_nodes"] == [i for i in range(k) if mask[i]]
    # one evaluation short of the budget: the GA runs instead
    assert search(spec, list(range(k)), SearchSettings(population=9, generations=7),
                  execution=Execution(workers=1))["search"]["method"] == "ga"


def test_cache_never_simulates_a_chromosome_twice(tmp_path):
    spec = linear(12, {1: 40.0, 6: 25.0, 9: 15.0}, log_dir=str(tmp_path))
    result = search(spec, NODES12, SearchSettings(**GA_BUDGET), execution=Execution(workers=1))
    seen = seen_masks(tmp_path)
    assert len(seen) == len(set(seen)) == result["search"]["unique_evaluations"]
    assert result["search"]["unique_evaluations"] < result["search"]["evaluations"]


def test_parsimony_drops_noise_level_nodes_and_keeps_real_ones():
    # node 0 repairs the model; node 2 lowers J by 0.5, below the noise (tolerance 1.34);
    # node 4 lowers it by 5, well above.
    spec = linear(6, {0: 50.0, 2: 0.5, 4: 5.0})
    noise = dict(noise_sigma=0.1, n_residuals=1000)
    assert parsimony.tolerance(100.0, **noise) == pytest.approx(3 * 0.01 * np.sqrt(2000))
    result = search(spec, list(range(6)), SearchSettings(population=8, generations=8),
                    execution=Execution(workers=1), **noise)
    assert result["search"]["min_nodes"] == [0, 2, 4]
    assert result["best_nodes"] == [0, 4]
    assert result["J_best"] == pytest.approx(45.0)


def test_parsimony_without_noise_estimate_uses_the_relative_floor():
    spec = linear(6, {0: 50.0, 2: 0.5})  # 0.5 < 1 % of J_unforced = 1.0
    result = search(spec, list(range(6)), SearchSettings(population=8, generations=8),
                    execution=Execution(workers=1))
    assert result["best_nodes"] == [0]


def test_nothing_helps_gives_no_nodes():
    spec = linear(6, {3: 0.2})  # a gain far below the noise, every other node harmful
    result = search(spec, list(range(6)), SearchSettings(population=8, generations=8),
                    execution=Execution(workers=1), noise_sigma=0.1, n_residuals=1000)
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
        result = search(spec, NODES12, SearchSettings(**GA_BUDGET), execution=Execution(workers=1))
    assert result["best_nodes"] == [3]
    assert result["node_scores"]["9"] is None
    assert 9 not in result["ranked_nodes"]
    assert any("simulation failed" in r.message and "solver diverged" in r.message
               for r in caplog.records)


def test_a_forcing_that_only_compensates_locates_nothing():
    # forcing node 2 lowers J by a fifth, well beyond the noise, but leaves most of the error:
    # the fault is where no forcing reaches (the paper's inside-convection case)
    spec = linear(6, {2: 20.0}, base=100.0)
    result = search(spec, [1, 2, 3, 4, 5, 6], execution=Execution(workers=1), noise_sigma=0.05, n_residuals=400)
    assert result["search"]["min_nodes"] == [3]
    assert result["ranked_nodes"] == [3]
    assert result["best_nodes"] == []
    # the same gain, when it removes most of the error, locates node 3
    located = search(linear(6, {2: 90.0}, base=100.0), [1, 2, 3, 4, 5, 6], execution=Execution(workers=1),
                     noise_sigma=0.05, n_residuals=400)
    assert located["best_nodes"] == [3]


@pytest.mark.slow  # processes, a cluster or a whole diagnosis: not in `make check`
def test_a_crashing_worker_only_loses_its_own_chromosome():
    # the best chromosome, nodes 1 and 3, kills its worker: the next best wins
    spec = linear(3, {0: 10.0, 2: 5.0}, penalty=20.0, crash_mask=(True, False, True))
    result = search(spec, [1, 2, 3], SearchSettings(population=4, generations=2),
                    execution=Execution(workers=2))
    assert result["search"]["method"] == "exhaustive"
    assert result["search"]["min_nodes"] == [1]
    assert result["search"]["J_min"] == pytest.approx(90.0)
    assert result["node_scores"]["3"] == pytest.approx(95.0)
    assert result["search"]["unique_evaluations"] == 8


def test_same_seed_same_result():
    first = search(TWELVE, NODES12, SearchSettings(seed=3, **GA_BUDGET), execution=Execution(workers=1))
    again = search(TWELVE, NODES12, SearchSettings(seed=3, **GA_BUDGET), execution=Execution(workers=1))
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
    uninterrupted = search(TWELVE, NODES12, SearchSettings(**budget), execution=Execution(workers=1))
    spec = linear(12, {1: 40.0, 6: 25.0, 9: 15.0}, log_dir=str(tmp_path))
    path = tmp_path / "out" / "search.json"
    with pytest.raises(Interrupt):
        search(spec, NODES12, SearchSettings(**budget), execution=Execution(workers=1, progress=stop_after(7)),
               checkpoint=path)
    resumed = search(spec, NODES12, SearchSettings(**budget), execution=Execution(workers=1), checkpoint=path)
    assert without_time(resumed) == without_time(uninterrupted)
    seen = seen_masks(tmp_path)  # the resumed run simulated nothing twice
    assert len(seen) == len(set(seen)) == resumed["search"]["unique_evaluations"]
    # a finished run's checkpoint answers a rerun without simulating anything
    rerun = search(spec, NODES12, SearchSettings(**budget), execution=Execution(workers=1), checkpoint=path)
    assert without_time(rerun) == without_time(uninterrupted)
    assert len(seen_masks(tmp_path)) == len(seen)


def test_checkpoint_of_other_arguments_is_not_resumed(tmp_path):
    path = tmp_path / "search.json"
    with pytest.raises(Interrupt):
        search(TWELVE, NODES12, SearchSettings(seed=0, **GA_BUDGET),
               execution=Execution(workers=1, progress=stop_after(5)), checkpoint=path)
    other = search(TWELVE, NODES12, SearchSettings(seed=1, **GA_BUDGET), execution=Execution(workers=1),
                   checkpoint=path)
    assert without_time(other) == without_time(search(TWELVE, NODES12, SearchSettings(seed=1, **GA_BUDGET),
                                                      execution=Execution(workers=1)))


@pytest.mark.slow  # processes, a cluster or a whole diagnosis: not in `make check`
def test_two_worker_processes_give_the_same_result(tmp_path):
    serial = search(TWELVE, NODES12, SearchSettings(**GA_BUDGET), execution=Execution(workers=1))
    spec = linear(12, {1: 40.0, 6: 25.0, 9: 15.0}, log_dir=str(tmp_path))
    parallel = search(spec, NODES12, SearchSettings(**GA_BUDGET), execution=Execution(workers=2))
    assert without_time(parallel) == without_time(serial)
    assert evaluators_built(tmp_path) == [1, 1]  # one evaluator per worker process


@pytest.mark.slow  # processes, a cluster or a whole diagnosis: not in `make check`
def test_searches_in_a_command_s_workers_run_in_its_processes_and_close_what_they_leave(tmp_path):
    # a diagnosis's searches (on the records together, then on each) and its rounds share its workers
    serial = search(TWELVE, NODES12, SearchSettings(**GA_BUDGET), execution=Execution(workers=1))
    logs = [tmp_path / "first", tmp_path / "second"]
    with lifetime.worker_pool(2) as workers:
        results = []
        for log in logs:
            log.mkdir()
            results.append(search(linear(12, {1: 40.0, 6: 25.0, 9: 15.0}, log_dir=str(log)), NODES12,
                                  SearchSettings(**GA_BUDGET), execution=Execution(workers=workers)))
        processes = set(workers.pool._processes)
        first, second = (evaluator_logs(log) for log in logs)
        # every evaluator in the pool's two processes, the second search's in those of the first
        assert len(processes) == 2 and first and second and set(first) | set(second) <= processes
        # the second search's evaluator closed the first's in every process it came to; the
        # processes stay for the stages after it
        assert all(first[pid] == ["built", "closed"] for pid in second if pid in first)
        assert all(said == ["built"] for said in second.values())
    assert all(without_time(r) == without_time(serial) for r in results)
    # the pool's end closes what the last search left
    assert all(said == ["built", "closed"] for said in evaluator_logs(logs[1]).values())


@pytest.mark.slow  # processes, a cluster or a whole diagnosis: not in `make check`
def test_dask_cluster_gives_the_same_result(tmp_path):
    distributed = pytest.importorskip("distributed")
    budget = dict(population=20, generations=15)
    serial = search(TWELVE, NODES12, SearchSettings(**budget), execution=Execution(workers=1))
    spec = linear(12, {1: 40.0, 6: 25.0, 9: 15.0}, log_dir=str(tmp_path))
    with distributed.LocalCluster(n_workers=2, processes=True, threads_per_worker=1,
                                  dashboard_address=None) as cluster:
        on_dask = search(spec, NODES12, SearchSettings(**budget),
                         execution=Execution(scheduler=cluster.scheduler_address))
    assert without_time(on_dask) == without_time(serial)
    # one evaluator per Dask worker that ran tasks: the scheduler, not nodeforce, places them, and on
    # busy cores it may give every task to the worker that answered first
    built = evaluators_built(tmp_path)
    assert 1 <= len(built) <= 2 and set(built) == {1}, built


# --- the default search: seeded from the single-node scores and a forward-backward pass, stopped
# at convergence; the paper's search (PAPER) is the same GA without either.


def test_forward_backward_adds_what_pays_and_drops_what_no_longer_does():
    # nodes 0 and 1 each lower J by 30 alone, but together only by 31 (they explain the same
    # fault); node 2 lowers it by 25 alone and by 25 in any company. Greedy: 0 (70), then 2
    # (45), then 1 would lower J by 1, under the tolerance: stop at {0, 2}.
    spec = Synthetic((-30.0, -30.0, -25.0, 4.0), pairs=((0, 1, 29.0),))
    evaluator = spec()
    mask, J = parsimony.forward_backward(lambda ms: [evaluator.J(m) for m in ms], 4, tol=2.0)
    assert mask == (True, False, True, False) and J == pytest.approx(45.0)
    # a node that paid when it came in is dropped once a later one makes it redundant:
    # node 1 alone is best (-30), node 0 then lowers J by 20 more, after which node 1 alone
    # adds only 1 on top of node 0 (pair interaction), so the pass drops it.
    spec = Synthetic((-49.0, -30.0, 0.5), pairs=((0, 1, 28.0),))
    evaluator = spec()
    mask, J = parsimony.forward_backward(lambda ms: [evaluator.J(m) for m in ms], 3, tol=2.0)
    assert mask == (True, False, False) and J == pytest.approx(51.0)


def test_forward_backward_stops_at_nothing_when_nothing_pays():
    evaluator = linear(5, {2: 0.5})()
    mask, J = parsimony.forward_backward(lambda ms: [evaluator.J(m) for m in ms], 5, tol=1.0)
    assert mask == (False,) * 5 and J == 100.0


def test_default_search_beats_the_stepwise_pass_on_an_interaction():
    # Nodes 4 and 7 lower J only together (each alone raises it): no single score, so no
    # stepwise pass, can find them; the GA must. The forward-backward pass stops at node 0.
    weights = [-10.0] + [1.0] * 11
    spec = Synthetic(tuple(weights), pairs=((4, 7, -60.0),))
    result = search(spec, NODES12, SearchSettings(seed=1, **LONG_GA), execution=Execution(workers=1))
    s = result["search"]
    assert s["stepwise_nodes"] == [1] and s["J_stepwise"] == pytest.approx(90.0)
    assert s["min_nodes"] == [1, 9, 15] and s["J_min"] == pytest.approx(32.0)
    assert result["best_nodes"] == [1, 9, 15]
    assert s["stopped"] == "converged" and s["stopped_at"] < s["generations"]


def test_convergence_stops_patience_generations_after_the_last_significant_fall():
    history = []
    result = search(TWELVE, NODES12, SearchSettings(patience=7, **LONG_GA),
                    execution=Execution(workers=1, progress=lambda g, total, J, unique: history.append(J)))
    s = result["search"]
    assert s["stopped"] == "converged" and s["stopped_at"] == len(history)
    tol = s["tolerance"]
    # the best J before the GA is the stepwise pass's; no later fall exceeded the tolerance by
    # the last `patience` generations, and the rule did not fire earlier
    falls, ref = [], s["J_stepwise"]
    for g, J in enumerate(history, start=1):
        if J < ref - tol:
            falls.append(g)
            ref = J
    assert s["stopped_at"] - (falls[-1] if falls else 0) == 7
    assert result["best_nodes"] == [3, 13, 19]


def test_paper_mode_is_the_unseeded_ga_to_the_last_generation(tmp_path):
    singles = ["0" * 12] + ["".join("1" if i == j else "0" for j in range(12)) for i in range(12)]
    for mode, settings in (("default", {}), ("paper", PAPER)):
        (tmp_path / mode).mkdir()
        spec = linear(12, {1: 40.0, 6: 25.0, 9: 15.0}, log_dir=str(tmp_path / mode))
        result = search(spec, NODES12, SearchSettings(**{**settings, **GA_BUDGET}),
                        execution=Execution(workers=1))
        first = seen_masks(tmp_path / mode)[:13]  # one process: in the order simulated
        if mode == "paper":
            # PyGAD's random first population, every generation run, no stepwise pass
            assert first != singles
            assert result["search"]["stopped"] == "generations"
            assert result["search"]["stopped_at"] == GA_BUDGET["generations"]
            assert "stepwise_nodes" not in result["search"]
        else:
            # the unforced and single-node scores come first, then the stepwise pass
            assert first == singles
            assert result["search"]["stepwise_nodes"] == [3, 13, 19]
        assert result["best_nodes"] == [3, 13, 19]


def test_a_converged_run_resumes_as_finished(tmp_path):
    path = tmp_path / "search.json"
    spec = linear(12, {1: 40.0, 6: 25.0, 9: 15.0}, log_dir=str(tmp_path))
    first = search(spec, NODES12, SearchSettings(patience=5, **LONG_GA), execution=Execution(workers=1),
                   checkpoint=path)
    assert first["search"]["stopped"] == "converged"
    seen = len(seen_masks(tmp_path))
    again = search(spec, NODES12, SearchSettings(patience=5, **LONG_GA), execution=Execution(workers=1),
                   checkpoint=path)
    assert without_time(again) == without_time(first)
    assert len(seen_masks(tmp_path)) == seen  # nothing simulated again


@pytest.mark.slow  # processes, a cluster or a whole diagnosis: not in `make check`
def test_the_fmu_evaluators_leave_no_extracted_folder(tmp_path, monkeypatch, testcell_data, testcell,
                                                      weather):
    # A private temp dir, so folders other processes make in the shared one do not count;
    # TMPDIR reaches the spawned workers.
    fmu = build_fmu(testcell, tmp_path / "cell.fmu")
    measurements = pseudo_measurements(testcell, weather, record_times(days=1), list(SENSORS))
    case = prepare_case(testcell, weather, measurements)
    factory = FmuFitness(fmu, case, [1, 7, 9], Objective.of(testcell), warmup_days=1)
    private = tmp_path / "tmp"
    private.mkdir()
    monkeypatch.setenv("TMPDIR", str(private))
    monkeypatch.setattr(tempfile, "tempdir", None)  # gettempdir() reads TMPDIR again
    assert tempfile.gettempdir() == str(private)
    during = []
    progress = lambda g, total, J, unique: during.append(len(list(private.iterdir())))  # noqa: E731
    for workers in (1, 2):
        search(factory, [1, 7, 9], SearchSettings(population=4, generations=2),
               execution=Execution(workers=workers, progress=progress))
        assert during[-1] >= 1  # the evaluators had extracted the FMU there
        assert list(private.iterdir()) == []
    # on failure too: a search stopped by an exception closes its evaluators
    with pytest.raises(Interrupt):
        search(factory, [1, 7, 9], SearchSettings(population=4, generations=2),
               execution=Execution(workers=2, progress=stop_after(1)))
    assert list(private.iterdir()) == []


def test_parsimony_prefers_the_earlier_node_only_when_the_noise_cannot_separate():
    # J_unforced 1000: tolerance = the relative floor, 10; the noise alone (sigma 0.1, n 1000)
    # separates sets whose J differ by more than 1.34. J_min = 0 (node 3 forced).
    noise = dict(noise_sigma=0.1, n_residuals=1000)
    assert parsimony.noise_tolerance(**noise) == pytest.approx(3 * 0.01 * np.sqrt(2000))
    assert parsimony.tolerance(1000.0, **noise) == pytest.approx(10.0)
    # node 0 compensates the fault at node 3 and fits the tolerance (J 5), but node 3 repairs it
    # (J 0), measurably better: node 3 is the answer though node 0 comes first
    spec = Synthetic((-995.0, 0.0, 0.0, -1000.0), pairs=((0, 3, 995.0),), base=1000.0)
    result = search(spec, [1, 2, 3, 4], SearchSettings(population=4, generations=4),
                    execution=Execution(workers=1), **noise)
    assert result["best_nodes"] == [4]
    # within the noise of each other (J 1 and 0), the earlier one is preferred
    spec = Synthetic((-999.0, 0.0, 0.0, -1000.0), pairs=((0, 3, 999.0),), base=1000.0)
    result = search(spec, [1, 2, 3, 4], SearchSettings(population=4, generations=4),
                    execution=Execution(workers=1), **noise)
    assert result["best_nodes"] == [1]


def test_parsimony_finds_the_pair_whatever_the_best_chromosome():
    # Two faults, nodes 2 and 5; node 0 compensates most of node 2's and its pair with 5 fits the
    # tolerance too, but measurably worse. Whatever chromosome the search ends on, the pair is
    # looked for among all pairs, so a best chromosome holding node 0 does not make it [0, 5].
    spec = Synthetic((-8.0, 1.0, -10.0, 1.0, 1.0, -80.0), pairs=((0, 2, 8.0),), base=100.0)
    evaluator = spec()
    J_many = lambda ms: [evaluator.J(m) for m in ms]  # noqa: E731
    best = (True, False, True, False, False, True)  # J = 10, with node 0 riding along
    assert parsimony.smallest_subset(J_many, best, evaluator.J(best) + 3.0, noise_tol=0.5) == \
        (False, False, True, False, False, True)


def test_the_finding_says_what_the_best_forcing_removes_and_what_the_sensors_cover(testcell):
    from nodeforce.ga.locate import finding
    # node 3 forced removes 20 of the 99 C2 above the noise floor (400 x 0.05^2 = 1 C2): 20 %
    result = search(linear(6, {2: 20.0}, base=100.0), [1, 2, 3, 4, 5, 6], execution=Execution(workers=1),
                    noise_sigma=0.05, n_residuals=400)
    said = finding(testcell, result)
    assert "No forcing locates the fault" in said
    assert "the best, forcing node 3 (west_wall at 0.000 m), removes 20% of J above the noise floor" in said
    assert "below the 50% needed" in said
    # nodes 1-6 belong to the east, west and south walls: 3 of the test cell's 8 components
    assert "Only 3 of the 8 components" in said and "east_wall, west_wall, south_wall" in said
    located = finding(testcell, search(linear(6, {2: 90.0}, base=100.0), [1, 2, 3, 4, 5, 6],
                                       execution=Execution(workers=1), noise_sigma=0.05, n_residuals=400))
    assert located.startswith("forcing node 3 (west_wall at 0.000 m) removes 91% of J above the noise floor")


def test_nodes_are_ranked_by_their_score_and_the_ones_the_noise_cannot_separate_are_tied():
    """Issue 27: the nodes were "ranked" in chromosome order when all lay within the tolerance.
    They are ranked by J; ties are marked, not reordered."""
    from nodeforce.ga.search import rank, ties
    J_single = [5.0, 3.0, 3.2, 9.0, 1.0, 12.0]
    assert rank(J_single, 10.0) == [4, 1, 2, 0, 3]  # node 5 (12.0) lowers nothing
    assert ties(J_single, 10.0, 0.5) == [[1, 2]]
    assert ties(J_single, 10.0, 2.5) == [[4, 1, 2]]  # 3.0 and 3.2 within 2.5 of 1.0; 5.0 and 9.0 alone


def test_the_finding_names_the_rule_that_decided(testcell):
    """A forcing that removes 80 % of the error above the noise but whose fall of J the noise could
    make is not called "below the 50 % needed"; one below half is; a node that removes more than
    the one the parsimony preferred is named with it; the evidence per component is its best node's
    share, most first."""
    from nodeforce.ga.locate import evidence, finding
    result = {"J_unforced": 2.0, "J_best": 2.0, "best_nodes": [], "ranked_nodes": [16, 9],
              "node_scores": {"16": 1.2, "9": 1.5, "17": 1.3, "7": 2.1}, "chromosome_nodes": [7, 9, 16, 17],
              "search": {"J_noise": 1.0, "J_min": 1.2, "min_nodes": [16], "tolerance": 0.9, "explains": True}}
    said = finding(testcell, result)
    assert "removes 80% of J above the noise floor" in said and "below the 50%" not in said
    assert "its fall of J, 0.8 C2, is within the 0.9 C2 the noise could make" in said
    weak = {**result, "search": {**result["search"], "J_min": 1.7, "explains": False}}
    assert "removes 30% of J above the noise floor, below the 50% needed" in finding(testcell, weak)
    located = {**result, "best_nodes": [9], "J_best": 1.5}
    assert "node 16 (floor at 0.150 m) alone removes more (80%)" in finding(testcell, located)
    shares = evidence(testcell, result)
    assert [(e["component"], e["node"]) for e in shares] == [("floor", 16), ("roof", 9), ("door", 7)]
    assert [e["share"] for e in shares] == pytest.approx([0.8, 0.5, -0.1])


def test_the_terminal_marks_the_nodes_the_noise_cannot_separate():
    from nodeforce.ga.locate import Localization
    result = {"J_unforced": 3.0, "objective": ["cell"], "node_scores": {"7": 1.0, "9": 1.1, "16": 2.0},
              "ranked_nodes": [7, 9, 16], "tied_nodes": [[7, 9]], "best_nodes": [7], "J_best": 1.0,
              "finding": "forcing node 7 ...", "search": {"method": "exhaustive", "unique_evaluations": 8,
                                                          "seconds": 0.1}}
    lines = Localization.of({"measured_nodes": [7, 9, 16, 23], "output_node": 23, "output_nodes": [23],
                             "chromosome_nodes": [7, 9, 16], "noise": {}, "components": [], **result}).summary().splitlines()
    header = next(i for i, line in enumerate(lines) if "J forced alone" in line)
    assert [line.split() for line in lines[header + 1:header + 4]] == [["7", "1.000", "a"], ["9", "1.100", "a"],
                                                                      ["16", "2.000"]]


@pytest.mark.parametrize("settings,option", [(dict(population=1), "--population"), (dict(generations=0), "--generations"),
                                             (dict(pc=1.5), "--pc"), (dict(pm=-0.1), "--pm"),
                                             (dict(patience=0), "--patience")])
def test_the_search_refuses_its_settings_as_the_command_line_does(settings, option):
    """One check of the GA's settings (`ga.search.check_settings`), where a `SearchSettings` is
    made, for the command's options and the API's arguments alike: the same InputError, naming
    the option, before any evaluation."""
    from nodeforce.ga.search import check_settings
    from nodeforce.model.errors import InputError
    with pytest.raises(InputError, match=option):
        SearchSettings(**settings)
    defaults = dict(population=30, generations=400, pc=0.8, pm=0.03, patience=None)
    with pytest.raises(InputError, match=option):
        check_settings(**{**defaults, **settings})
