"""The step loop of cosim/fmi.py: compiled (c/master.c) it makes the calls the loop in Python
makes, with the same values, for FMI 2.0 and 3.0 and both kinds of FMU, and names a call that
fails as the loop in Python does."""
import numpy as np
import pytest
from fmpy.fmi1 import FMICallException

from nodeforce.cosim import fmi
from nodeforce.cosim.fmi import FmuInstance
from nodeforce.cosim.run import simulate_fmu
from nodeforce.fmu_build.build import build_fmu, fmu_kind
from nodeforce.model.building_file import parse_building
from nodeforce.runtime import compiler as compiled_library

pytestmark = pytest.mark.skipif(compiled_library.find_compiler() is None, reason="no C compiler: the steps are looped in Python")

KINDS = [("python", 2), ("standalone", 2), ("python", 3), ("standalone", 3)]


@pytest.fixture(scope="module")
def fmus(tmp_path_factory, testcell_data):
    folder = tmp_path_factory.mktemp("loop")
    building = parse_building(testcell_data)
    return {(kind, version): build_fmu(building, folder / f"{kind}{version}.fmu", kind=fmu_kind(kind, version))
            for kind, version in KINDS}


def in_python(monkeypatch):
    monkeypatch.setattr(fmi, "_master", lambda: None)


@pytest.mark.parametrize("kind", KINDS, ids=lambda k: f"{k[0]}-fmi{k[1]}")
def test_the_compiled_loop_gives_the_loop_in_python_s_numbers_bit_for_bit(fmus, real_case, monkeypatch, kind):
    """A run with a warm-up left unread (skip), input slopes and forced nodes, whose forcing
    changes (NaN where a node is left computed): every output the same double."""
    force = np.zeros(real_case.measured.shape[1], dtype=bool)
    force[[0, 8, 16]] = True
    with FmuInstance(fmus[kind]) as instance:
        compiled = simulate_fmu(instance, real_case, force)
        again = simulate_fmu(instance, real_case, force)
        in_python(monkeypatch)
        looped = simulate_fmu(instance, real_case, force)
    assert np.array_equal(compiled, looped) and np.array_equal(compiled, again)
    assert np.ptp(looped[:, 22]) > 2.0  # a run, not an idle model


@pytest.mark.parametrize("version", (2, 3))
def test_a_failed_call_stops_the_compiled_loop_and_is_named_as_in_python(fmus, monkeypatch, version):
    """The standalone FMU refuses a doStep of more than its sub-steps' limit: both loops raise
    FMPy's FMICallException naming that call and its status (fmiError), and the instance, reset,
    runs again."""
    air = ["T[23]"]

    def run(instance, dt):
        return instance.run(dt, {}, {}, [], np.empty((len(dt), 0)), air)

    dt = np.full(6, 900.0)
    too_long = dt.copy()
    too_long[3] = 1e12
    raised = []
    with FmuInstance(fmus[("standalone", version)]) as instance:
        fine = run(instance, dt)
        for loop in ("compiled", "python"):
            if loop == "python":
                in_python(monkeypatch)
            with pytest.raises(FMICallException) as caught:
                run(instance, too_long)
            raised.append((caught.value.function, caught.value.status))
            assert np.array_equal(run(instance, dt), fine)
    assert raised == [(f"fmi{version}DoStep", 3)] * 2


def test_a_compiler_that_fails_leaves_the_loop_to_python(fmus, real_case, monkeypatch, caplog):
    """Said once in the log; the run is the same."""
    with FmuInstance(fmus[("standalone", 2)]) as instance:
        compiled = simulate_fmu(instance, real_case)

        def fails(*args, **kwargs):
            raise RuntimeError("compiling 'master.c' failed: cc: error: unrecognized option")
        monkeypatch.setattr(compiled_library, "built_library", fails)
        fmi._master.cache_clear()
        try:
            with caplog.at_level("WARNING", logger="nodeforce.cosim"):
                looped = simulate_fmu(instance, real_case)
                assert fmi._master() is None
            assert caplog.text.count("looped in Python: compiling 'master.c' failed") == 1
        finally:
            fmi._master.cache_clear()  # compiled again by the next run
    assert np.array_equal(compiled, looped)
