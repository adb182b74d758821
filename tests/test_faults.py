"""Faults, for real: runs killed or stopped by signals leave nothing running and nothing behind
and resume to the same answer; the folders of dead processes go at the next run; a Dask worker
lost mid-search costs no answer and a lost scheduler leaves a resumable checkpoint.

Every run is a process of its own session (start_new_session), so "its processes" are those of
that session, workers included; each test has its own temp directory (TMPDIR), so folders of
other runs on the machine do not count.
"""
import copy
import json
import logging
import os
import signal
import subprocess
import sys
import time
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import pytest

from nodeforce.runtime import lifetime, tempdirs
from nodeforce.cli import main
from nodeforce.ga import checkpoint as ckpt
from nodeforce.ga.search import Execution, SearchSettings, search
from nodeforce.model.building_file import parse_building
from nodeforce.model.synth import pseudo_measurements
from tests.conftest import DATA, SENSORS, record_times
from tests.test_search import NODES12, TWELVE, without_time

ROOT = Path(__file__).parents[1]
GONE_WITHIN = 60.0  # s: a bound on the wait, so that a process left alive fails the test rather than hangs it


@pytest.fixture(scope="module")
def cell(tmp_path_factory, testcell_data, weather):
    """The test cell, and measurements of it with a door conducting 0.78 W/m/K, not 0.23: two
    days of the six sensors (a search of 32 chromosomes) and six days of the door and the air
    only (a diagnosis whose search is over at once and whose calibrations come soon)."""
    d = tmp_path_factory.mktemp("faults")
    building = d / "cell.json"
    building.write_text(json.dumps(testcell_data))
    disturbed = copy.deepcopy(testcell_data)
    disturbed["materials"]["wood"]["conductivity"] = 0.78
    disturbed = parse_building(disturbed)
    two_days = pseudo_measurements(disturbed, weather, record_times(days=2), SENSORS)
    two_days.to_csv(d / "measured.csv", date_format="%Y-%m-%dT%H:%M:%S%z")
    six_days = pseudo_measurements(disturbed, weather, record_times(days=6), [7, 23], noise_sd=0.1, seed=1)
    six_days.to_csv(d / "door_air.csv", date_format="%Y-%m-%dT%H:%M:%S%z")
    weather_file = str(DATA / "miami_tmy2.csv")
    # the records start in the periodic regime of their first day (no history), as the model is told
    return {"locate": ["locate", str(building), "--weather", weather_file, "--measurements",
                       str(d / "measured.csv"), "--population", "4", "--generations", "8", "--history-days", "0"],
            "diagnose": ["diagnose", str(building), "--weather", weather_file, "--measurements",
                         str(d / "door_air.csv")]}


def session(sid):
    """The live processes of session `sid` (zombies, which run no more, left out)."""
    pids = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                stat = (entry / "stat").read_text()
            except OSError:
                continue
            state, _, _, session_id = stat[stat.rindex(")") + 2:].split()[:4]
            if int(session_id) == sid and state not in "ZX":
                pids.append(int(entry.name))
    return pids


# `nodeforce` with a hook that sends the command's own process a signal at a point of its run
# chosen by the test, so where the run stops does not depend on the machine's load: "generation N"
# once the search's N-th generation (its checkpoint written) is over, "calibrating" once the first
# candidate of a round is back from the workers and the others are still being calibrated.
SIGNALLING = """
import os, signal, sys
from nodeforce.runtime import lifetime
from nodeforce.__main__ import main
from nodeforce.ga import search
when, signum, arguments = sys.argv[1], int(sys.argv[2]), sys.argv[3:]
if when.startswith("generation "):
    at, step = int(when.split()[1]), search._Steps.step
    def stepped(self, generation, **extra):
        step(self, generation, **extra)
        if generation == at:
            os.kill(os.getpid(), signum)
    search._Steps.step = stepped
else:
    collected = lifetime.collected
    def first_back(results, done=None):
        def arrived():
            if done is not None:
                done()
            os.kill(os.getpid(), signum)
        return collected(results, arrived)
    lifetime.collected = first_back
sys.exit(main(arguments))
"""


def start_signalled(arguments, signum, when):
    """`nodeforce ARGUMENTS` as a process of its own session, which sends itself `signum` `when`
    (`SIGNALLING`)."""
    return subprocess.Popen([sys.executable, "-c", SIGNALLING, when, str(int(signum)), *arguments], cwd=ROOT,
                            text=True, start_new_session=True, stdout=subprocess.PIPE, stderr=subprocess.PIPE)


def wait_for(condition, seconds, what):
    deadline = time.monotonic() + seconds
    while not condition():
        assert time.monotonic() < deadline, f"{what}: not within {seconds} s"
        time.sleep(0.05)


def ended(run):
    """Wait for the run to end; return (exit status, stderr, seconds from its end until every
    process of its session had ended)."""
    _, err = run.communicate(timeout=600)
    gone = time.monotonic()
    wait_for(lambda: not session(run.pid), GONE_WITHIN, "processes of the stopped run are still alive")
    return run.returncode, err, time.monotonic() - gone


@pytest.mark.slow
def test_a_locate_killed_outright_takes_its_workers_with_it(cell, tmp_path, private_tmp):
    out = tmp_path / "out"
    run = start_signalled(cell["locate"] + ["-o", str(out), "--workers", "2"], signal.SIGKILL, "generation 2")
    status, _, seconds = ended(run)
    assert status == -signal.SIGKILL
    assert json.loads((out / ckpt.NAME).read_text())["generation"] == 2
    print(f"SIGKILL of locate --workers 2: its processes gone {seconds:.2f} s later")
    # the workers, signalled by the parent's death, removed the FMUs they had extracted
    assert os.listdir(private_tmp) == []


@pytest.mark.slow
def test_a_diagnosis_killed_while_calibrating_takes_its_workers_with_it(cell, tmp_path, private_tmp):
    out = tmp_path / "out"
    run = start_signalled(cell["diagnose"] + ["-o", str(out), "--workers", "2"], signal.SIGKILL, "calibrating")
    status, _, seconds = ended(run)
    assert status == -signal.SIGKILL
    assert (out / "candidates").is_dir()
    print(f"SIGKILL of diagnose --workers 2 while calibrating: its processes gone {seconds:.2f} s later")
    # a process killed outright cannot remove its own folders (the parent's extracted FMU, or a
    # worker's caught mid-extraction): what is left is the dead run's, and the next run sweeps it
    left = os.listdir(private_tmp)
    assert all(name.startswith("nodeforce_") and not tempdirs.owner_alive(name) for name in left), left
    tempdirs.sweep(private_tmp)
    assert os.listdir(private_tmp) == []


@pytest.mark.slow
def test_sigterm_stops_a_locate_cleanly_and_its_checkpoint_resumes_to_the_same_answer(
        cell, tmp_path, private_tmp, capsys):
    out = tmp_path / "stopped"
    arguments = cell["locate"] + ["-o", str(out), "--workers", "2"]
    status, err, seconds = ended(start_signalled(arguments, signal.SIGTERM, "generation 3"))
    print(f"SIGTERM of locate --workers 2: its processes gone {seconds:.2f} s later")
    assert status == 128 + signal.SIGTERM == 143
    [line] = err.splitlines()  # one line, no traceback
    assert line.startswith(f"nodeforce: stopped by SIGTERM; run the same command again to resume from "
                           f"{out / ckpt.NAME} (generation 3")
    assert os.listdir(private_tmp) == []  # the workers' extracted FMUs removed
    assert sorted(p.name for p in out.iterdir()) == [ckpt.NAME, "model.fmu"]  # no half-written file
    # stopped where the signal came, midway: 32 chromosomes, 4 a generation
    assert json.loads((out / ckpt.NAME).read_text())["generation"] == 3

    assert main(arguments) == 0  # the same command again: resumes
    assert main(cell["locate"] + ["-o", str(tmp_path / "whole"), "--workers", "1"]) == 0
    resumed, whole = (json.loads((tmp_path / name / "locate.json").read_text()) for name in ("stopped", "whole"))
    assert without_time(resumed) == without_time(whole)
    assert resumed["best_nodes"] == [7]  # the door, whose conductivity the measurements changed
    assert os.listdir(private_tmp) == []


def test_the_next_run_removes_the_folders_of_dead_processes_only(tmp_path, private_tmp):
    dead = subprocess.Popen(["true"])
    dead.wait()  # its pid now names no process
    me = os.getpid()
    tag = tempdirs.owner_tag()
    started = int(tag.split("-")[1])
    folders = {
        "dead": f"nodeforce_fmu_{dead.pid}-{started}_abc",
        "alive": f"nodeforce_fmu_{tag}_abc",
        "pid_reused": f"nodeforce_fmu_{me}-{started + 1}_abc",  # this pid, another process's start time
        "no_owner": "nodeforce_fmu_x3k9q2",  # an earlier release's name: whose it is cannot be known
    }
    for name in folders.values():
        (private_tmp / name).mkdir()
        (private_tmp / name / "model.so").write_bytes(b"\0")
    building = tmp_path / "cell.json"
    building.write_text((DATA / "testcell_miami.json").read_text())
    assert main(["fmu", str(building), "-o", str(tmp_path / "cell.fmu")]) == 0
    assert sorted(os.listdir(private_tmp)) == sorted([folders["alive"], folders["no_owner"]])


@dataclass(frozen=True)
class SignalledFmu:
    """TWELVE's evaluator inside an FMU whose own code catches every exception and reports a
    failed step, as pythonfmu's does: a SIGTERM coming at its `n`-th simulation raises there."""
    n: int

    def __call__(self):
        return SignalledEvaluator(self.n)


class SignalledEvaluator:
    def __init__(self, n):
        self.left, self.inner = n, TWELVE()

    def J(self, mask):
        self.left -= 1
        try:
            if self.left == 0:
                os.kill(os.getpid(), signal.SIGTERM)
            return self.inner.J(mask)
        except BaseException as exc:
            raise RuntimeError(f"fmi2DoStep failed: {exc!r}") from None


def test_a_signal_the_fmu_reports_as_a_failed_step_stops_the_search_and_scores_nothing_unfit(tmp_path):
    path = tmp_path / "search.json"
    with pytest.raises(lifetime.Interrupted), lifetime.stop_on_signals() as signals:
        search(SignalledFmu(n=100), NODES12, SearchSettings(**BUDGET), execution=Execution(workers=1),
               checkpoint=path)
    saved = json.loads(path.read_text())
    assert saved["generation"] >= 1 and None not in saved["cache"].values()
    assert lifetime.stopped(RuntimeError(), signals) == (143, "stopped by SIGTERM")
    lifetime.raise_if_interrupted()  # the block is over: a later failed simulation is one again


# --- Dask: a loopback cluster of scheduler and worker processes started here (free ports)


@dataclass(frozen=True)
class Killing:
    """TWELVE's evaluator, which SIGKILLs `victim` (None: its own worker process) at the first
    mask it scores once the file `armed` exists; the file `done` says it did, so only once."""
    armed: str
    done: str
    victim: "int | None" = None

    def __call__(self):
        return KillingEvaluator(self)


class KillingEvaluator:
    def __init__(self, spec):
        self.spec, self.inner = spec, TWELVE()

    def J(self, mask):
        if os.path.exists(self.spec.armed):
            try:
                os.close(os.open(self.spec.done, os.O_CREAT | os.O_EXCL))
            except FileExistsError:
                pass
            else:
                os.kill(self.spec.victim or os.getpid(), signal.SIGKILL)
        return self.inner.J(mask)


def arm_after(generation, armed):
    def progress(g, total, J, unique):
        if g == generation:
            Path(armed).touch()
    return progress


@contextmanager
def dask_cluster(folder, n_workers, threads=1):
    """`dask scheduler` on 127.0.0.1 (a port the system picks) and `dask worker`s (with their
    nannies, which restart a killed worker); yields (address, scheduler process). The cluster is
    killed outright at the end: a worker caught holding a temporary folder (compiling the steps
    at its first run) cannot remove it, and the folders of its dead processes are swept, as the
    next nodeforce command would (`tempdirs.sweep`)."""
    from distributed import Client
    file = folder / "scheduler.json"
    env = {**os.environ, "PYTHONPATH": str(ROOT)}  # the workers unpickle this module's evaluators
    quiet = dict(cwd=ROOT, env=env, start_new_session=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    processes = [subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1",
                                   "--port", "0", "--no-dashboard", "--scheduler-file", str(file)], **quiet)]
    try:
        wait_for(file.exists, 60, "the Dask scheduler did not start")
        for _ in range(n_workers):
            processes.append(subprocess.Popen(
                [sys.executable, "-m", "distributed.cli.dask_worker", "--scheduler-file", str(file), "--host",
                 "127.0.0.1", "--nthreads", str(threads), "--no-dashboard", "--death-timeout", "30"], **quiet))
        address = json.loads(file.read_text())["address"]
        with Client(address, timeout="30s") as client:
            client.wait_for_workers(n_workers, timeout=60)
        yield address, processes[0]
    finally:
        for process in processes:
            try:
                os.killpg(process.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
            process.wait()
        tempdirs.sweep()


BUDGET = dict(population=20, generations=15)


@pytest.mark.slow
def test_a_dask_worker_killed_mid_search_costs_no_answer(tmp_path, caplog):
    spec = Killing(armed=str(tmp_path / "armed"), done=str(tmp_path / "killed"))
    # One worker process (two threads): the one killed is the one holding the evaluator factory
    # too, so the search goes on only once its nanny has restarted it and the scheduler has made
    # the factory again.
    with dask_cluster(tmp_path, 1, threads=2) as (address, _), caplog.at_level(logging.WARNING, "nodeforce.ga"):
        result = search(spec, NODES12, SearchSettings(**BUDGET),
                        execution=Execution(scheduler=address, progress=arm_after(2, spec.armed)))
    assert Path(spec.done).exists()  # a worker was killed, in the middle of a generation
    print(f"Dask worker killed: the search took {result['search']['seconds']:.1f} s")
    # the scheduler gave its task to a worker alive: no chunk was lost and retried mask by mask
    assert "a worker died" not in caplog.text
    assert without_time(result) == without_time(search(TWELVE, NODES12, SearchSettings(**BUDGET),
                                                       execution=Execution(workers=1)))


@pytest.mark.slow
def test_a_lost_dask_scheduler_stops_the_search_with_a_checkpoint_that_resumes(tmp_path):
    path = tmp_path / "search.json"
    with dask_cluster(tmp_path, 1) as (address, scheduler):
        spec = Killing(armed=str(tmp_path / "armed"), done=str(tmp_path / "killed"), victim=scheduler.pid)
        with pytest.raises(lifetime.RunStopped) as stopped:
            search(spec, NODES12, SearchSettings(**BUDGET),
                   execution=Execution(scheduler=address, progress=arm_after(2, spec.armed)), checkpoint=path)
        print(f"lost scheduler: the search stopped {time.time() - os.path.getmtime(spec.done):.2f} s after "
              "the scheduler was killed")
    [line] = str(stopped.value).splitlines()
    assert line.startswith(f"--scheduler: {address}: lost the Dask scheduler (")
    assert json.loads(path.read_text())["generation"] >= 2  # the generations done before the loss
    # nothing scored unfit for the loss: the rerun, here in this process, gives the whole answer
    resumed = search(spec, NODES12, SearchSettings(**BUDGET), execution=Execution(workers=1), checkpoint=path)
    assert without_time(resumed) == without_time(search(TWELVE, NODES12, SearchSettings(**BUDGET),
                                                        execution=Execution(workers=1)))
