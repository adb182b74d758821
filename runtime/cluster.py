"""The Dask plumbing, in one place: a run's client of a dask.distributed scheduler, the data
every task of a batch reads shipped once to every worker, and batches mapped over the workers
so that a lost worker costs no answer and a lost scheduler stops the run in one line.

    with Cluster("tcp://host:port") as cluster:     # InputError naming --scheduler if unreachable
        shared = cluster.share(value)               # on every worker, once
        results = cluster.map(function, items, shared)  # function(value, item) per item

The forcing search (`ga.evaluation.DaskBackend`: its evaluator factory shared, its chunks of
masks mapped) and the diagnosis (`diagnosis.loop.assess_all`: a round's model and records
shared, its candidates mapped) both run through it.

A worker lost mid-task (killed, its machine gone) costs nothing: the scheduler gives its tasks
to another worker (or to the same one, restarted by its nanny); if the shared data were lost
with it (every worker holding them gone), they are shipped again and the tasks that needed them
submitted again. A task that killed three workers in turn (Dask's `allowed-failures`) comes back
as its exception, for the caller to judge. A lost scheduler raises `lifetime.RunStopped`.
"""
import logging

from nodeforce.runtime import lifetime
from nodeforce.model.errors import InputError

# The client's own logs are silenced while it serves a run: every failure it meets reaches the
# run as a future's exception, said in one line (a lost scheduler), and they would repeat it as
# tracebacks (a closed connection, the attempts to reconnect).
CLIENT_LOGGERS = ("distributed.client", "distributed.batched")
# Times a batch is submitted while the workers holding its shared data are lost (a task that
# kills every worker it runs on must not be retried for ever).
SHARED_LOSSES = 3


class Shared:
    """A value on every worker of a cluster (`Cluster.share`), shipped again if it was lost."""

    def __init__(self, client, value):
        self._client, self._value = client, value
        self.ship()

    def ship(self):
        [self.future] = self._client.scatter([self._value], broadcast=True, hash=False)

    @property
    def lost(self) -> bool:
        """Whether every worker that held it is gone (scattered data cannot be made again)."""
        return self.future.status != "finished"


class Cluster:
    """A run's client of the Dask scheduler at `address` ("tcp://host:port"); a context manager
    that closes the client (the cluster stays up)."""

    def __init__(self, address: str):
        from distributed import Client

        try:
            self.client = Client(address, set_as_default=False, timeout="10s")
        except (OSError, ValueError, TypeError) as e:
            raise InputError("--scheduler", address, f"cannot reach a Dask scheduler there ({e})") from None
        self.address = address
        self._log_levels = {name: logging.getLogger(name).level for name in CLIENT_LOGGERS}
        for name in CLIENT_LOGGERS:
            logging.getLogger(name).setLevel(logging.CRITICAL + 1)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    @property
    def slots(self) -> int:
        """Threads of the workers now connected (at least 1)."""
        return max(1, sum(self.client.nthreads().values()))

    def share(self, value) -> Shared:
        """`value` shipped once to every worker, for the tasks of `map` to read."""
        return Shared(self.client, value)

    def map(self, function, items, shared: "Shared | None" = None, done=None) -> list:
        """function(shared value, item) (function(item) without `shared`) for each item on the
        workers; per item its result or the exception that ended it (its own, or KilledWorker),
        for the caller to judge. `done(index, that)` is called as each item ends (a progress bar's
        update, a result kept at once).
        Raises `lifetime.RunStopped` if the scheduler is lost."""
        from distributed import as_completed

        results = [None] * len(items)
        todo = range(len(items))
        for attempt in range(SHARED_LOSSES):
            extra = () if shared is None else (shared.future,)
            futures = {self.client.submit(function, *extra, items[i], pure=False): i for i in todo}
            todo = []
            for future in as_completed(futures, loop=self.client.loop):
                i = futures[future]
                try:
                    results[i] = future.result()
                except Exception as exc:  # KilledWorker, a task's own error, the scheduler gone
                    if self.client.status != "running":
                        raise lifetime.RunStopped(f"--scheduler: {self.address}: lost the Dask scheduler "
                                                  f"({type(exc).__name__})") from exc
                    results[i] = exc
                    if shared is not None and shared.lost and attempt < SHARED_LOSSES - 1:
                        todo.append(i)
                        continue
                if done is not None:
                    done(i, results[i])
            if not todo:
                break
            if shared is not None:
                shared.ship()
        return results

    def map_shared(self, function, value, items, done=None) -> list:
        """function(value, item) for each item on the workers, `value` shipped once to every
        worker (`share`); the results in the order of `items`, `done()` as each ends; a task's
        error raised once every task has ended (`lifetime.Workers.map_shared` on a cluster)."""
        results = self.map(function, items, self.share(value), done=None if done is None else lambda *_: done())
        for result in results:
            if isinstance(result, BaseException):
                raise result
        return results

    def run(self, function, *args):
        """function(*args) once in every worker process (not as a task)."""
        return self.client.run(function, *args)

    def close(self):
        try:
            self.client.close()
        finally:
            for name, level in self._log_levels.items():
                logging.getLogger(name).setLevel(level)
