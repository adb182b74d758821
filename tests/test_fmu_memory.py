"""The Python FMU leaves its host's memory intact: when the model raises, and when the host
exits, as FMI 2.0 and as FMI 3.0 (its FMI 3.0 interface, fmu_build/c/fmi3.c, calls the guard).
pythonfmu 0.7.0's binary releases Python objects twice in both cases (fmu_build/c/guard.c says
how the guard keeps the host out of it), and so does pythonfmu3 0.3.4's (docs/fmu.md). Each case
runs in a process of its own, so that a corrupted heap ends that process, not the test session."""
import json
import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from nodeforce.fmu_build.build import build_fmu, fmu_kind
from nodeforce.model.building_file import parse_building
from tests.test_standalone import python_host_environment, run_c_host, scenario

ERROR = 3  # fmi2Error and fmi3Error
ROOT = Path(__file__).parents[1]

# Twelve times the model raising, each followed by Reset and a valid run, through
# nodeforce's own FMI 2.0 or 3.0 calls (cosim/fmi.py). Without the guard's care pythonfmu's
# instance loses one reference to the slave class at each, and the process ends in a
# segmentation fault by the fourth.
RAISES_AND_RECOVERS = textwrap.dedent("""
    import json, sys
    import numpy as np
    from fmpy import extract, read_model_description
    from fmpy.fmi1 import FMICallException
    from nodeforce.cosim.fmi import VERSIONS

    fmu, unzipped = sys.argv[1], sys.argv[2]
    md = read_model_description(fmu)
    calls = VERSIONS[md.fmiVersion](md)
    slave = calls.slave_class(guid=md.guid, unzipDirectory=extract(fmu, unzipdir=unzipped),
                              modelIdentifier=md.coSimulation.modelIdentifier, instanceName="memory")
    slave.instantiate(loggingOn=True)

    def run(U):
        calls.initialise(slave, 0.0, {}, {"ground_coupling.U": U})
        T = np.empty((4, 1))
        calls.steps(slave, [], ["T[23]"]).run(900.0 * np.arange(4), np.full(4, 900.0), np.empty((4, 0)),
                                               np.empty((4, 0)), T, 0)
        return T[-1, 0]

    answers = []
    for attempt in range(12):
        try:
            run(-1.0)
            answers.append(None)
        except FMICallException as e:
            answers.append(e.status)
        slave.reset()
        answers.append(run(2.0))
        slave.reset()
    slave.freeInstance()
    print("ANSWERS " + json.dumps(answers), flush=True)
""")


@pytest.fixture(scope="module")
def coupled_fmu(tmp_path_factory, testcell_data):
    """{FMI version: the test cell's Python FMU with a ground coupling of the floor as parameters}."""
    folder = tmp_path_factory.mktemp("memory")
    return {fmi: build_fmu(parse_building(testcell_data), folder / f"coupled{fmi}.fmu",
                           effect=("ground_coupling", "floor"), kind=fmu_kind("python", fmi))
            for fmi in (2, 3)}


def python_process(script, *args, env=None, prefix=()):
    """A Python process running `script` from the repository root, started through `prefix` (a
    tool such as valgrind) if given; its output captured."""
    return subprocess.run([*prefix, sys.executable, "-c", script, *map(str, args)], cwd=ROOT, env=env,
                          capture_output=True, text=True, timeout=600)


@pytest.mark.parametrize("fmi", (2, 3))
def test_a_model_that_raises_gets_fmi_error_and_reset_recovers_it(coupled_fmu, tmp_path, fmi):
    """A negative ground conductance is refused by the model (an exception in Python): the call
    is answered Error (not pythonfmu's or pythonfmu3's Fatal, after which nothing may be called),
    the reason is logged, and Reset gives an instance whose run is the same as the first one's."""
    done = python_process(RAISES_AND_RECOVERS, coupled_fmu[fmi], tmp_path / "unzipped")
    assert done.returncode == 0, f"exit {done.returncode}\n{done.stdout[-2000:]}\n{done.stderr[-2000:]}"
    answers = json.loads(done.stdout.split("ANSWERS ")[1])
    refused, runs = answers[0::2], answers[1::2]
    assert refused == [ERROR] * 12
    assert all(np.isfinite(runs)) and len(set(runs)) == 1
    # the model's reason: its building check
    assert done.stdout.count("components[7].outside.h: -1.0 is less than or equal to the minimum of 0") == 12
    assert done.stdout.count("answers fmi2Error until fmi2Reset") == 12


# The lifecycle of an FMU in nodeforce's own host: extracted, instantiated, run, reset and run,
# freed, and the process ends.
LIFECYCLE = textwrap.dedent("""
    import sys
    import numpy as np
    from nodeforce.cosim.fmi import FmuInstance

    with FmuInstance(sys.argv[1]) as instance:
        names = instance.names("input")
        for run in range(2):
            T = instance.run(900.0, {}, {}, names, np.zeros((8, len(names))), ["T[23]"])
    print("RAN", T[-1, 0])
""")


def freed_memory_touched(log):
    """Valgrind's reports of a read, write or free of memory already freed: its blocks (separated
    by an empty "==pid==" line) with a line that starts "Invalid" and that say where the memory
    was "free'd"."""
    lines = [line.split("== ", 1)[-1] if line.startswith("==") else line for line in log.splitlines()]
    blocks = "\n".join(line if line.strip("= 0123456789") else "" for line in lines).split("\n\n")
    return [b for b in blocks if "free'd" in b and any(line.startswith("Invalid") for line in b.splitlines())]


def valgrind(tmp_path):
    tool = shutil.which("valgrind") or pytest.fail("this test needs valgrind (make system-deps installs it)")
    return [tool, "--error-exitcode=0", f"--log-file={tmp_path / 'valgrind.%p.log'}"]


def valgrind_logs(tmp_path):
    return "\n".join(p.read_text() for p in sorted(tmp_path.glob("valgrind.*.log")))


@pytest.mark.slow  # valgrind: tens of seconds
@pytest.mark.parametrize("fmi", (2, 3))
def test_a_python_host_ends_without_touching_freed_memory(tmp_path, testcell_data, fmi):
    """pythonfmu's binary stays loaded to the end of a process and, at exit, released its Python
    state a second time: freed memory written, which glibc reported now and then as "corrupted
    double-linked list". Valgrind sees each such access, whether or not glibc notices."""
    fmu = build_fmu(parse_building(testcell_data), tmp_path / "model.fmu", kind=fmu_kind("python", fmi))
    env = dict(os.environ, PYTHONMALLOC="malloc")  # Python's own allocator hides accesses from valgrind
    done = python_process(LIFECYCLE, fmu, env=env, prefix=valgrind(tmp_path))
    assert done.returncode == 0 and "RAN" in done.stdout, done.stderr[-2000:]
    log = valgrind_logs(tmp_path)
    assert "ERROR SUMMARY" in log
    assert freed_memory_touched(log) == []


@pytest.mark.slow  # valgrind: tens of seconds
def test_a_c_host_ends_without_touching_freed_memory(tmp_path, testcell_data):
    """In a C host pythonfmu starts Python and ends it at exit: the same double release there."""
    fmu = build_fmu(parse_building(testcell_data), tmp_path / "model.fmu")
    parameters, inputs, outputs, _ = scenario(fmu)
    env = dict(python_host_environment(), PYTHONMALLOC="malloc")
    done, T = run_c_host(fmu, parameters, inputs, outputs, 900.0, 4, tmp_path, env=env,
                         prefix=valgrind(tmp_path))
    assert done.returncode == 0 and T.shape == (4, len(outputs)), done.stderr[-2000:]
    log = valgrind_logs(tmp_path)
    assert "ERROR SUMMARY" in log
    assert freed_memory_touched(log) == []
