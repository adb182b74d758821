"""Scoring chromosomes: J per forcing mask, cached, run in-process, in worker processes or on Dask.

A chromosome (Lauret et al.) is a mask over the measured nodes: True = that node is forced to
its measured temperature for the whole run.  Its score is J, the sum of squared residuals of
indoor air temperature (docs/model.md section 6), computed by an *evaluator*:

    factory = SomeFactory(...)      # picklable; shipped to every worker
    evaluator = factory()           # called once per worker process (or per Dask worker thread)
    evaluator.J(mask)               # mask: tuple[bool, ...] over the chromosome nodes, in order
    evaluator.close()               # optional; every backend calls it when it shuts down

J may raise: the simulation failed.  That chromosome is then unfit (J = inf, fitness 0), the
reason is logged on logger "nodeforce.ga", and the search goes on.  A worker process that dies
(a crash inside a C library) is handled the same way: its masks are retried one at a time in a
fresh worker and the one that kills it again is scored unfit.  Only a factory that fails to
build an evaluator stops the search (EvaluatorSetupError): that is a setup error, not a bad
chromosome.
"""

from __future__ import annotations

import hashlib
import logging
import math
import multiprocessing.util
import pickle
import threading
from contextlib import ExitStack
from functools import partial
from typing import Iterable, Sequence

from nodeforce.runtime import lifetime
from nodeforce.runtime.cluster import Cluster

log = logging.getLogger("nodeforce.ga")

Mask = tuple[bool, ...]
# What a worker returns for one mask: (J, None) or (inf, reason it failed).
Outcome = tuple[float, "str | None"]


class EvaluatorSetupError(RuntimeError):
    """The evaluator factory itself failed in a worker: no chromosome can be scored."""


def factory_token(factory) -> str:
    """A stable name for a factory: hash of its pickle (same arguments -> same token)."""
    return hashlib.sha256(pickle.dumps(factory, protocol=4)).hexdigest()


def evaluate_masks(evaluator, masks: Iterable[Mask]) -> list[Outcome]:
    """Score masks one by one with one evaluator; a failed simulation becomes (inf, reason)."""
    outcomes = []
    for mask in masks:
        try:
            J = float(evaluator.J(tuple(mask)))
        except Exception as exc:  # any failure of the simulation makes the chromosome unfit
            lifetime.raise_if_interrupted()  # unless it was a signal, reported by the FMU
            outcomes.append((math.inf, f"{type(exc).__name__}: {exc}"))
            continue
        outcomes.append((J, None) if math.isfinite(J) else (math.inf, f"J is {J}"))
    return outcomes


def close_evaluator(evaluator) -> None:
    """Release what an evaluator holds (an FMU instance and its extracted files), if it says how."""
    close = getattr(evaluator, "close", None)
    if close is not None:
        close()


def _build(factory):
    try:
        return factory()
    except Exception as exc:
        raise EvaluatorSetupError(f"evaluator factory failed: {type(exc).__name__}: {exc}") from exc


# --- backends: each runs a list of chunks (lists of masks) and returns, per chunk, either its
# outcomes or the exception that lost the whole chunk (a dead worker).  Used as context managers:
# a search ended by an exception (a signal's included) stops them without waiting for the work
# in progress (close(abort=True)).


class _Backend:
    def __enter__(self):
        return self

    def __exit__(self, kind, *rest):
        self.close(abort=kind is not None)


class InProcessBackend(_Backend):
    """workers=1: one evaluator in this process, no pool."""

    slots = 1

    def __init__(self, factory):
        self._evaluator = _build(factory)

    def run(self, chunks):
        return [evaluate_masks(self._evaluator, chunk) for chunk in chunks]

    def close(self, abort=False):
        close_evaluator(self._evaluator)


# Per worker process: the search in progress's (path of its factory, evaluator, finaliser that
# closes it), the evaluator built on the search's first task there from the factory it shares
# (`lifetime.shared`). A later search in the same processes (a command's `lifetime.Workers`)
# closes it.
_process_evaluator = None


def _pool_task(path, masks):
    global _process_evaluator
    if _process_evaluator is None or _process_evaluator[0] != path:
        if _process_evaluator is not None:
            _process_evaluator[2]()
            _process_evaluator = None
        evaluator = _build(lifetime.read_shared(path))
        # closed at the latest when the worker exits, which the pool's shutdown makes it do
        # (multiprocessing runs its finalisers at a worker's normal exit)
        _process_evaluator = (path, evaluator, multiprocessing.util.Finalize(
            evaluator, close_evaluator, args=(evaluator,), exitpriority=10))
    return evaluate_masks(_process_evaluator[1], masks)


class ProcessBackend(_Backend):
    """Worker processes, each building its own evaluator from the factory on its first chunk:
    `workers`, a command's `lifetime.Workers` that other stages use after the search, or a count
    of processes started for the search alone; they end with this process (runtime.lifetime).
    A worker that dies (a crash in a C library) breaks the pool: the processes are started anew."""

    def __init__(self, factory, workers: "int | lifetime.Workers"):
        self._own = not isinstance(workers, lifetime.Workers)
        self._workers = lifetime.Workers(workers) if self._own else workers
        self.slots = self._workers.count
        self._shared = ExitStack()
        self._task = partial(_pool_task, self._shared.enter_context(lifetime.shared(factory)))

    def run(self, chunks):
        futures = [self._workers.submit(self._task, chunk) for chunk in chunks]
        results, broken = [], False
        for future in futures:
            try:
                results.append(future.result())
            except EvaluatorSetupError:
                raise
            except Exception as exc:  # BrokenProcessPool: a worker died, the pool is unusable
                results.append(exc)
                broken = True
        if broken:
            self._workers.renew()
        return results

    def close(self, abort=False):
        try:
            if self._own:
                self._workers.close(abort)
        finally:
            self._shared.close()


# Per Dask worker process: evaluators keyed by (factory token, thread), built on first use.
# One per thread because an evaluator (an FMU instance) is not safe to share between threads.
_dask_evaluators: dict = {}


def _dask_task(token: str, factory, masks):
    key = (token, threading.get_ident())
    if key not in _dask_evaluators:
        _dask_evaluators[key] = _build(factory)
    return evaluate_masks(_dask_evaluators[key], masks)


def _dask_close(token: str) -> None:
    """Run on every Dask worker when a search ends: its evaluators go, the cluster stays up."""
    for key in [key for key in _dask_evaluators if key[0] == token]:
        close_evaluator(_dask_evaluators.pop(key))


class DaskBackend(_Backend):
    """Chunks mapped over the workers of a dask.distributed scheduler through `runtime.cluster`
    (`cluster`: its address, "tcp://host:port", or a command's `Cluster`, which it leaves
    open), the factory shipped once to every worker.

    A worker lost mid-task costs nothing (its tasks rerun, the factory is shipped again if it was
    lost with it); a lost scheduler stops the search (lifetime.RunStopped); its checkpoint
    resumes it.
    """

    def __init__(self, factory, cluster: "str | Cluster"):
        self._own = not isinstance(cluster, Cluster)
        self._cluster = Cluster(cluster) if self._own else cluster
        self._token = factory_token(factory)
        self._task = partial(_dask_task, self._token)
        self._factory = self._cluster.share(factory)

    @property
    def slots(self) -> int:
        return self._cluster.slots

    def run(self, chunks):
        results = self._cluster.map(self._task, chunks, self._factory)
        for result in results:
            if isinstance(result, EvaluatorSetupError):
                raise result
        return results

    def close(self, abort=False):
        try:
            if not abort:  # the workers keep the evaluators of a stopped search, for its rerun
                self._cluster.run(_dask_close, self._token)
        finally:
            if self._own:
                self._cluster.close()


def open_backend(factory, workers: "int | lifetime.InProcess | lifetime.Workers | Cluster", scheduler: "str | None"):
    """The backend the caller asked for: Dask if a scheduler address is given, else where
    `workers` runs tasks: a count of processes (1: this process), or a command's own
    (`lifetime.InProcess`, `lifetime.Workers`, a `Cluster`), which its later stages use too."""
    if scheduler is not None or isinstance(workers, Cluster):
        return DaskBackend(factory, scheduler if scheduler is not None else workers)
    if workers == 1 or isinstance(workers, lifetime.InProcess):
        return InProcessBackend(factory)
    return ProcessBackend(factory, workers)


def _split(items: Sequence, parts: int) -> list[list]:
    """Split into at most `parts` contiguous chunks of near-equal size (one task per slot)."""
    parts = max(1, min(parts, len(items)))
    size, extra = divmod(len(items), parts)
    chunks, start = [], 0
    for i in range(parts):
        end = start + size + (1 if i < extra else 0)
        chunks.append(list(items[start:end]))
        start = end
    return chunks


class FitnessCache:
    """J per mask; a chromosome already scored is never simulated again.

    `requests` counts the J values the search asked for (cache hits included); the number of
    simulations actually run is len(self.J_of) (failed ones included).
    """

    def __init__(self, backend, known: "dict[Mask, float] | None" = None, node_ids=None):
        self._backend = backend
        self._node_ids = node_ids
        self.J_of: dict[Mask, float] = dict(known or {})
        self.requests = 0

    @property
    def unique(self) -> int:
        return len(self.J_of)

    def J_many(self, masks: Sequence[Mask], count: bool = True) -> list[float]:
        """J for each mask; the uncached ones go to the workers together, as one batch."""
        masks = [tuple(bool(b) for b in m) for m in masks]
        if count:
            self.requests += len(masks)
        todo = list(dict.fromkeys(m for m in masks if m not in self.J_of))
        if todo:
            self._simulate(todo)
        return [self.J_of[m] for m in masks]

    def _simulate(self, todo: list[Mask]):
        chunks = _split(todo, self._backend.slots)
        for chunk, result in zip(chunks, self._backend.run(chunks)):
            if isinstance(result, BaseException):
                result = self._isolate(chunk, result)
            for mask, (J, reason) in zip(chunk, result):
                if reason is not None:
                    log.warning("forcing nodes %s: simulation failed, scored unfit: %s",
                                self.describe(mask), reason)
                self.J_of[mask] = J

    def _isolate(self, chunk, error) -> list[Outcome]:
        # A dead worker lost the whole chunk; rerun its masks one at a time, sequentially, so a
        # second crash points at a single mask and does not take innocent ones with it.
        log.warning("a worker died evaluating %d chromosomes (%s); retrying them one by one",
                    len(chunk), error)
        outcomes = []
        for mask in chunk:
            [result] = self._backend.run([[mask]])
            outcomes.append((math.inf, f"worker died: {result}")
                            if isinstance(result, BaseException) else result[0])
        return outcomes

    def describe(self, mask: Mask) -> list:
        """The node ids a mask forces (positions if the cache was not given the ids)."""
        ids = self._node_ids if self._node_ids is not None else range(len(mask))
        return [n for n, bit in zip(ids, mask) if bit]

    def best(self) -> Mask:
        """The lowest-J mask scored so far; ties go to fewer forced nodes, then mask order."""
        return min(self.J_of, key=lambda m: (self.J_of[m], sum(m), m))
