"""The Python FMU leaves its host's memory intact: when the model raises, and when the host
exits. pythonfmu 0.7.0's binary releases Python objects twice in both cases (fmu_build/c/guard.c
says how the guard keeps the host out of it). Each case runs in a process of its own, so that a
corrupted heap ends that process, not the test session."""
import json
import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from nodeforce.fmu_build.build import build_fmu
from nodeforce.model.building import parse_building
from tests.test_standalone import python_host_environment, run_c_host, scenario

ERROR = 3  # fmi2Status
ROOT = Path(__file__).parents[1]

# Twelve times the model raising, each followed by fmi2Reset and a valid run. Without the guard's
# care pythonfmu's instance loses one reference to the slave class at each, and the process ends
# in a segmentation fault by the fourth.
RAISES_AND_RECOVERS = textwrap.dedent("""
    import json, sys
    from fmpy import extract, read_model_description
    from fmpy.fmi1 import FMICallException
    from fmpy.fmi2 import FMU2Slave

    fmu, unzipped = sys.argv[1], sys.argv[2]
    md = read_model_description(fmu)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    slave = FMU2Slave(guid=md.guid, unzipDirectory=extract(fmu, unzipdir=unzipped),
                      modelIdentifier=md.coSimulation.modelIdentifier, instanceName="memory")
    slave.instantiate(loggingOn=True)

    def run(U):
        slave.setupExperiment(startTime=0.0)
        slave.enterInitializationMode()
        slave.setReal([vr["ground_coupling.U"]], [U])
        slave.exitInitializationMode()
        for k in range(4):
            slave.doStep(currentCommunicationPoint=900.0 * k, communicationStepSize=900.0)
        return slave.getReal([vr["T[23]"]])[0]

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
    """The test cell's Python FMU with a ground coupling of the floor as parameters."""
    return build_fmu(parse_building(testcell_data), tmp_path_factory.mktemp("memory") / "coupled.fmu",
                     effect=("ground_coupling", "floor"))


def python_process(script, *args, env=None, prefix=()):
    """A Python process running `script` from the repository root, started through `prefix` (a
    tool such as valgrind) if given; its output captured."""
    return subprocess.run([*prefix, sys.executable, "-c", script, *map(str, args)], cwd=ROOT, env=env,
                          capture_output=True, text=True, timeout=600)


def test_a_model_that_raises_gets_fmi2_error_and_reset_recovers_it(coupled_fmu, tmp_path):
    """A negative ground conductance is refused by the model (an exception in Python): the call
    is answered fmi2Error (not pythonfmu's fmi2Fatal, after which nothing may be called), the
    reason is logged, and fmi2Reset gives an instance whose run is the same as the first one's."""
    done = python_process(RAISES_AND_RECOVERS, coupled_fmu, tmp_path / "unzipped")
    assert done.returncode == 0, f"exit {done.returncode}\n{done.stdout[-2000:]}\n{done.stderr[-2000:]}"
    answers = json.loads(done.stdout.split("ANSWERS ")[1])
    refused, runs = answers[0::2], answers[1::2]
    assert refused == [ERROR] * 12
    assert all(np.isfinite(runs)) and len(set(runs)) == 1
    assert done.stdout.count("components[7].outside.h: must be > 0, found -1.0") == 12  # the model's reason
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
def test_a_python_host_ends_without_touching_freed_memory(tmp_path, testcell_data):
    """pythonfmu's binary stays loaded to the end of a process and, at exit, released its Python
    state a second time: freed memory written, which glibc reported now and then as "corrupted
    double-linked list". Valgrind sees each such access, whether or not glibc notices."""
    fmu = build_fmu(parse_building(testcell_data), tmp_path / "model.fmu")
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
