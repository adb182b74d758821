"""The diagnosis on a Dask cluster (`runtime.cluster`): the answer of the local run, a worker
lost in the middle of a round costs none, a lost scheduler stops it in one line. (The forcing search's own cluster tests are in
test_search.py and test_faults.py.)

The record: the test cell whose door conducts 0.78 W/m/K, not 0.23, six days of the door and the
air only, so that the search is over at once and the round's candidates are the cost.
"""
import copy
import os
import signal

import pytest

from nodeforce.runtime import lifetime
from nodeforce.diagnosis.loop import diagnose
from nodeforce.ga.locate import Execution, SearchSettings
from nodeforce.model.building_file import load_building, parse_building
from nodeforce.model.effects import EFFECTS
from nodeforce.model.case import prepare_case
from nodeforce.model.score import Objective
from nodeforce.model.synth import pseudo_measurements
from tests.conftest import record_times
from tests.test_faults import dask_cluster

pytestmark = pytest.mark.slow  # clusters and whole diagnoses: not in `make check`

distributed = pytest.importorskip("distributed")


@pytest.fixture(scope="module")
def door(testcell_data, testcell, weather):
    disturbed = copy.deepcopy(testcell_data)
    disturbed["materials"]["wood"]["conductivity"] = 0.78
    measured = pseudo_measurements(parse_building(disturbed), weather, record_times(days=6), [7, 23],
                                   noise_sd=0.1, seed=1)
    return testcell, prepare_case(testcell, weather, measured).with_burn_in(1)


@pytest.fixture(scope="module")
def local(door, tmp_path_factory):
    """The diagnosis in this process: the answer every cluster run must give."""
    folder = tmp_path_factory.mktemp("local")
    building, case = door
    return diagnose(building, case, folder, Objective.of(building), search=SearchSettings(seed=0),
                    execution=Execution(workers=1)).to_json(), folder


def cluster():
    return distributed.LocalCluster(n_workers=2, processes=True, threads_per_worker=1, dashboard_address=None)


def assert_same_answer(report, folder, local):
    expected, expected_folder = local
    # the choices, every round's
    assert report["effects"] == expected["effects"]
    assert [d["chosen"] for d in report["decision"]["rounds"]] == \
        [d["chosen"] for d in expected["decision"]["rounds"]]
    # every candidate, its calibrated parameters and its cross-validated error, to the rounding
    assert [(c["effect"], c["target"]) for c in report["candidates"]] == \
        [(c["effect"], c["target"]) for c in expected["candidates"]]
    for c, e in zip(report["candidates"], expected["candidates"]):
        for name, p in c["parameters"].items():
            assert p["value"] == pytest.approx(e["parameters"][name]["value"], rel=1e-9, abs=1e-12)
        assert c["cv"]["J"] == pytest.approx(e["cv"]["J"], rel=1e-9)
    assert report["after"]["validation"]["rmse"] == pytest.approx(expected["after"]["validation"]["rmse"], rel=1e-9)
    # the candidates' building files, which the workers sent back, written here as the local run's
    files = sorted(p.relative_to(expected_folder) for p in (expected_folder / "candidates").rglob("*.json"))
    assert files and files == sorted(p.relative_to(folder) for p in (folder / "candidates").rglob("*.json"))
    for file in files:
        effect, target = file.stem.split("@")
        ours, theirs = (EFFECTS[effect].read(load_building(f / file), target) for f in (folder, expected_folder))
        assert ours == pytest.approx(theirs, rel=1e-9, abs=1e-12), file


def test_a_diagnosis_on_a_two_worker_cluster_gives_the_local_answer(door, local, tmp_path):
    building, case = door
    with cluster() as c, distributed.Client(c.scheduler_address) as client, \
            distributed.get_task_stream(client) as stream:
        report = diagnose(building, case, tmp_path, Objective.of(building), search=SearchSettings(seed=0),
                          execution=Execution(scheduler=c.scheduler_address)).to_json()
    assert_same_answer(report, tmp_path, local)
    # every candidate was calibrated there, once: no worker was lost
    assert sum(task["key"].startswith("assess-") for task in stream.data) == len(report["candidates"])


def kill_at_first_candidate(done, victim=None):
    """In a worker process: the first candidate any worker starts kills `victim` (default its own
    process) outright (SIGKILL, as a machine lost); the file `done` says it happened, so only once."""
    from nodeforce.diagnosis import assess as task
    assess = task.assess

    def killing(shared, pair):
        try:
            os.close(os.open(done, os.O_CREAT | os.O_EXCL))
        except FileExistsError:
            return assess(shared, pair)
        os.kill(victim or os.getpid(), signal.SIGKILL)

    task.assess = killing


def test_a_worker_killed_in_the_middle_of_a_round_costs_no_answer(door, local, tmp_path):
    building, case = door
    done = tmp_path / "killed"
    with cluster() as c, distributed.Client(c.scheduler_address) as client, \
            distributed.get_task_stream(client) as stream:
        client.run(kill_at_first_candidate, str(done))
        report = diagnose(building, case, tmp_path / "out", Objective.of(building),
                          search=SearchSettings(seed=0),
                          execution=Execution(scheduler=c.scheduler_address)).to_json()
    assert done.exists()  # a worker was lost with a candidate in hand, the others under way
    # the scheduler gave its candidate to a worker alive: each one calibrated once to its end
    assert sum(task["key"].startswith("assess-") for task in stream.data) == len(report["candidates"])
    assert_same_answer(report, tmp_path / "out", local)


def test_a_lost_scheduler_stops_the_diagnosis_in_one_line(door, tmp_path):
    building, case = door
    done = tmp_path / "killed"
    with dask_cluster(tmp_path, 1) as (address, scheduler):
        with distributed.Client(address) as client:
            client.run(kill_at_first_candidate, str(done), scheduler.pid)
        with pytest.raises(lifetime.RunStopped) as stopped:
            diagnose(building, case, tmp_path / "out", Objective.of(building), search=SearchSettings(seed=0),
                     execution=Execution(scheduler=address))
    assert done.exists()  # lost in the round, its search done
    [line] = str(stopped.value).splitlines()
    assert line.startswith(f"--scheduler: {address}: lost the Dask scheduler (")
