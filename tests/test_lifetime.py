"""Worker pools share the cores: each worker's BLAS threads are its share, unless the user chose."""
import os

from threadpoolctl import threadpool_info

from nodeforce.runtime import lifetime


def blas_threads():
    """The worker's BLAS thread counts, after numpy has loaded its library."""
    import numpy as np
    np.linalg.inv(np.eye(3))
    return sorted({lib["num_threads"] for lib in threadpool_info() if lib["user_api"] == "blas"})


def test_each_worker_gets_its_share_of_the_cores_for_blas(monkeypatch):
    for name in lifetime.THREAD_VARIABLES:
        monkeypatch.delenv(name, raising=False)
    workers = os.cpu_count()
    with lifetime.worker_pool(workers) as pool:
        assert pool.submit(blas_threads).result() == [1]
    with lifetime.worker_pool(1) as pool:
        # one worker alone has every core
        assert pool.submit(blas_threads).result() == [os.cpu_count()]


def test_a_thread_count_the_user_set_is_kept(monkeypatch):
    monkeypatch.setenv("OPENBLAS_NUM_THREADS", "1")
    with lifetime.worker_pool(1) as pool:
        assert pool.submit(blas_threads).result() == [1]


def _shared_sum(values, task):
    """(the shared values' sum, how many times this worker has read a shared file)."""
    return float(values.sum()), lifetime.read_shared.cache_info().misses


def test_a_value_shared_with_a_pool_s_tasks_is_read_once_a_worker_and_removed_after(private_tmp):
    import numpy as np
    values = np.arange(50_000, dtype=float)
    with lifetime.worker_pool(2) as pool:
        answers = pool.map_shared(_shared_sum, values, range(12))
        assert not list(private_tmp.glob("nodeforce_shared_*"))
        again = pool.map_shared(_shared_sum, values[:10], range(12))  # another round: read again
    assert {total for total, _ in answers} == {values.sum()} and {total for total, _ in again} == {values[:10].sum()}
    # read once a worker a round: the first round's by each worker that ran a task, the second's once more
    assert {reads for _, reads in answers} == {1} and {reads for _, reads in again} <= {1, 2}
    try:
        with lifetime.shared(values):
            raise KeyboardInterrupt
    except KeyboardInterrupt:
        pass
    assert not list(private_tmp.glob("nodeforce_shared_*"))
