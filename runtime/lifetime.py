"""How a run ends when it is stopped: worker processes that end with their parent, SIGINT and
SIGTERM turned into a clean stop, and a distinct exit status for each way of stopping.

Worker pools (`new_pool`, `worker_pool`'s `Workers`) start their processes with "spawn"
(evaluators hold FMU and C-library state that must not be inherited through fork) and, in each
worker, before any task:

- on Linux, the parent-death signal (prctl PR_SET_PDEATHSIG) is SIGTERM, then the parent's pid
  is checked once more: a parent that died before the prctl would never send it. The kernel
  sends the signal when the thread that started the worker ends; nodeforce starts workers from
  the main thread, which lives as long as the process. Elsewhere a thread watches the parent;
- SIGINT is ignored: a Ctrl-C reaches the whole process group, and the parent decides;
- SIGTERM removes the worker's temporary folders (runtime.tempdirs) and ends it at once, with
  status 143. An FMU it holds is not freed: the process ends, and the system takes its memory;
- the BLAS and OpenMP thread pools get the worker's share of the cores (`share_cores`): a pool
  of as many workers as cores whose every numpy inverse also starts a thread per core asks the
  cores for twice what they have, and OpenBLAS's threads spin while they wait (measured on the
  Twin House's calibrations, 2 workers on 2 cores: the inverses took 68 % of the time, each
  2.3 times as long as with one thread).

So a parent killed outright (SIGKILL, the out-of-memory killer) takes its workers with it within
the time they take to see the signal (a Python FMU step, milliseconds), and a pool stopped by an
exception (`stop_pool`) does not wait for the work in progress.

In the `nodeforce` command (`stop_on_signals`), SIGINT and SIGTERM raise `Interrupted` in the
main thread, which unwinds the run like any exception (pools stopped, FMUs freed, temporary
folders removed); a second signal during that cleanup is ignored. The command then prints one
line and exits with 128 + the signal number, as shells report it: 130 for SIGINT, 143 for
SIGTERM. A run stopped by a cause outside its inputs that a rerun may not meet (a lost Dask
scheduler) raises `RunStopped` and exits with 75 (EX_TEMPFAIL of sysexits.h: try again).
"""
import ctypes
import functools
import multiprocessing
import os
import pickle
import signal
import sys
import threading
import time
from concurrent.futures import ProcessPoolExecutor
from contextlib import contextmanager
from pathlib import Path

from threadpoolctl import threadpool_limits

from nodeforce.runtime import tempdirs

PR_SET_PDEATHSIG = 1  # linux/prctl.h
# Seconds a stopped worker has to remove its folders and exit before it is killed.
STOP_GRACE = 5.0


class Interrupted(BaseException):
    """SIGINT or SIGTERM reached the run. A BaseException, like KeyboardInterrupt, so that no
    `except Exception` meant for a failed simulation takes it for one."""

    def __init__(self, signum):
        super().__init__(f"stopped by {signal.Signals(signum).name}")
        self.signum = signum


class RunStopped(RuntimeError):
    """The run cannot go on for a cause outside its inputs (a lost Dask scheduler); its
    checkpoint resumes it."""

    exit_status = 75


class Signals:
    """What `stop_on_signals` received: `signum`, the first signal (None: none came)."""

    signum: "int | None" = None


_current: "Signals | None" = None  # while a stop_on_signals block runs


def _on_signal(signum, frame):
    if _current.signum is None:  # the first one stops the run; later ones must not break its cleanup
        _current.signum = signum
        raise Interrupted(signum)


def raise_if_interrupted():
    """Raise Interrupted if a signal is stopping the run. For code that catches a failure: an FMU
    whose own Python code was running when the signal came reports an FMU error instead."""
    if _current is not None and _current.signum is not None:
        raise Interrupted(_current.signum)


@contextmanager
def stop_on_signals():
    """Within the block (in the main thread), SIGINT and SIGTERM raise Interrupted; yields the
    `Signals` received, for `stopped` after the block."""
    global _current
    _current = Signals()
    previous = {s: signal.signal(s, _on_signal) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield _current
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)
        _current = None


def stopped(exc: BaseException, signals: Signals) -> "tuple[int, str] | None":
    """(exit status, what stopped the run) if `exc` ended a run stopped from outside, else None.
    Any exception counts once a signal came: it may be the signal's, reported by an FMU."""
    if signals.signum is not None:
        return 128 + signals.signum, f"stopped by {signal.Signals(signals.signum).name}"
    if isinstance(exc, RunStopped):
        return exc.exit_status, str(exc)
    return None


# --- worker processes


def _worker_exit(signum, frame):
    tempdirs.remove_held()
    os._exit(128 + signum)


def _watch_parent(parent):
    while os.getppid() == parent:
        time.sleep(1.0)
    os.kill(os.getpid(), signal.SIGTERM)


# The variables the thread pools of the numerical libraries read when they load.
THREAD_VARIABLES = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


def share_cores(workers):
    """Limit this process's BLAS and OpenMP threads to its share of the cores, cores // workers
    (at least one), unless the user set them: in the libraries loaded now (threadpoolctl) and,
    through the environment they read when they load, in those loaded later."""
    threads = max(1, (os.cpu_count() or 1) // workers)
    if any(name in os.environ for name in THREAD_VARIABLES):
        return
    for name in THREAD_VARIABLES:
        os.environ[name] = str(threads)
    threadpool_limits(threads)


def _worker_start(parent, workers):
    share_cores(workers)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, _worker_exit)
    if sys.platform.startswith("linux"):
        ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGTERM, 0, 0, 0)
        if os.getppid() != parent:
            _worker_exit(signal.SIGTERM, None)
    else:
        threading.Thread(target=_watch_parent, args=(parent,), daemon=True).start()


def new_pool(workers: int) -> ProcessPoolExecutor:
    """A pool of `workers` spawned processes that end when this process ends (module docstring).
    What its tasks all read (a search's FMU and records, a round's model) reaches them through a
    file (`shared`), read once a worker: an initializer's arguments go through a pipe the parent
    writes whole before it starts the next worker, which kept it waiting while each worker
    imported what they need (3.5 s each for the Twin House's search)."""
    return ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context("spawn"),
                               initializer=_worker_start, initargs=(os.getpid(), workers))


def stop_pool(pool: ProcessPoolExecutor) -> None:
    """Stop a pool now: work not started is cancelled, work in progress abandoned. Each worker gets
    SIGTERM (it removes its folders and exits) and is killed if still there after STOP_GRACE;
    then the folders of killed workers are swept."""
    # The executor has no public way to end its workers before Python 3.14 (terminate_workers).
    processes = list((pool._processes or {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    for process in processes:
        if process.is_alive():
            process.terminate()
    deadline = time.monotonic() + STOP_GRACE
    killed = False
    for process in processes:
        process.join(max(0.0, deadline - time.monotonic()))
        if process.is_alive():
            process.kill()
            process.join()
            killed = True
    if killed:
        tempdirs.sweep()


@contextmanager
def shared(value):
    """The path of `value` pickled once to a folder of its own, for the tasks of a pool to read
    where they run (`read_shared`: once a worker) instead of each carrying it through the pipe
    (a round of the Twin House's candidates shares some 30 MB: 37 ms to pickle in the parent and
    13 ms to read, for every one of its 180 tasks). The folder goes at the block's end."""
    path = Path(tempdirs.make("shared")) / "shared.pickle"
    path.write_bytes(pickle.dumps(value, pickle.HIGHEST_PROTOCOL))
    path = str(path)
    try:
        yield path
    finally:
        tempdirs.remove(Path(path).parent)


@functools.lru_cache(maxsize=1)
def read_shared(path):
    """What `shared` wrote to `path`, read once in this process (the last one read is kept). The
    worker counts the folder among its own: a parent killed outright leaves it to its workers."""
    tempdirs.hold(Path(path).parent)
    return pickle.loads(Path(path).read_bytes())


def collected(results, done=None) -> list:
    """The results of an iterable in a list, `done()` called after each arrives (a progress
    bar's update)."""
    kept = []
    for result in results:
        kept.append(result)
        if done is not None:
            done()
    return kept


def _shared_task(function, path, item):
    """function(the value `shared` wrote to `path`, item): a task of `Workers.map_shared`."""
    return function(read_shared(path), item)


class InProcess:
    """A command's tasks run in this process, one after another (one worker asked for): what
    `Workers` and a Dask `runtime.cluster.Cluster` are for work spread over processes."""

    def map_shared(self, function, value, items, done=None) -> list:
        """function(value, item) for each item, in order; `done()` after each."""
        return collected((function(value, item) for item in items), done)


class Workers:
    """The worker processes of a command (`worker_pool`), which its stages share: the forcing
    search's evaluations and the rounds' candidates run in the same processes, whose start and
    imports (some 2 s each) are paid once. A stage that finds one of them dead (a crash in a C
    library: the pool is broken) starts them anew (`renew`), for itself and the stages after it."""

    def __init__(self, count: int):
        self.count = count
        self.pool = new_pool(count)

    def submit(self, fn, *args, **kwargs):
        return self.pool.submit(fn, *args, **kwargs)

    def map_shared(self, function, value, items, done=None) -> list:
        """function(value, item) for each item in the workers (`function` a module's, to be
        pickled), `value` written once to a file each worker reads once (`shared`); the results
        in the order of `items`, `done()` after each; a task's error raised."""
        with shared(value) as path:
            return collected(self.pool.map(functools.partial(_shared_task, function, path), items), done)

    def renew(self):
        """New processes in place of a broken pool (its work lost, its workers gone)."""
        self.pool.shutdown(wait=False, cancel_futures=True)
        self.pool = new_pool(self.count)

    def close(self, abort=False):
        """Shut the processes down once their work is done, or, `abort`, stop them now
        (`stop_pool`): an error or a signal does not wait for the work in progress."""
        if abort:
            stop_pool(self.pool)
        else:
            self.pool.shutdown(wait=True)


@contextmanager
def worker_pool(workers: int):
    """`Workers` for a `with` block: closed at its end, stopped when the block raises."""
    processes = Workers(workers)
    try:
        yield processes
    except BaseException:
        processes.close(abort=True)
        raise
    processes.close()
