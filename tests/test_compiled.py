"""The compiled runs of steps (`model.compiled`, model/c/steps.c) against the step itself
(`ImplicitEuler.step`, numpy's inverse, one step at a time) and a recurrence solved by hand."""
from pathlib import Path

import numpy as np
import pytest

from nodeforce.model import compiled
from nodeforce.runtime import compiler
from nodeforce.model.building_file import load_building
from nodeforce.model.integrate import ImplicitEuler, Sources
from nodeforce.model.network import assemble

ROOT = Path(__file__).parents[1]
TESTCELL = ROOT / "model" / "data" / "testcell.json"
HOUSE = ROOT / "examples" / "twinhouse_n2" / "building.json"

pytestmark = pytest.mark.skipif(not compiled.available(), reason="no C compiler: the steps are numpy's")


def test_one_node_s_steps_are_the_recurrence_solved_by_hand():
    # C/dt = c, one conductance G to a node held at 0: (c + G) T^k+1 = c T^k + v^k, v = b u + q constant
    c, G, b, u, q, T0 = 4.0, 1.0, 2.0, 1.25, 0.5, 10.0
    v = b * u + q
    pattern = (np.array([0, 1], dtype=np.int32), np.array([0], dtype=np.int32))
    sources = Sources(np.full((50, 1), u), np.array([[b]]), np.array([q]))
    path, last = compiled.steps((pattern, np.array([c + G])), np.array([c]), sources, [], None, np.array([T0]), [0])
    k = np.arange(1, 51)
    lam = c / (c + G)
    expected = lam ** k * T0 + v / (c + G) * (1 - lam ** k) / (1 - lam)
    assert np.abs(path[:, 0] - expected).max() < 1e-12
    assert last[0] == path[-1, 0]


def stepped(stepper, T, sources, forced, imposed, switched):
    out = []
    for source, T_forced in zip(sources, imposed):
        T = stepper.step(T, source, forced, T_forced, switched)
        out.append(T)
    return np.array(out)


@pytest.mark.parametrize("path, forced_ids, switch", [(TESTCELL, (), False), (TESTCELL, (1, 7, 9, 16, 17, 23), True),
                                                      (HOUSE, (), False), (HOUSE, (1, 40, 41, 120), True)],
                         ids=["test cell", "test cell, forced and switched", "Twin House (air carried one way)",
                              "Twin House, forced and switched"])
def test_a_compiled_run_is_the_steps_to_rounding(path, forced_ids, switch):
    network = assemble(load_building(path))
    n = network.n_nodes
    stepper = ImplicitEuler(network, 300.0)
    rng = np.random.default_rng(2)
    L = 1500
    sources = Sources(*network.source_terms(10.0 + 5.0 * rng.normal(size=(L, len(network.input_names)))))
    forced = np.zeros(n, dtype=bool)
    forced[[i - 1 for i in forced_ids]] = True
    switched = np.where(rng.random(n) < 0.1, 5.0, 0.0) if switch else None
    imposed = 20.0 + rng.normal(size=(L, n))
    T0 = np.linspace(10.0, 30.0, n)
    T0[forced] = np.nan  # what a forced node held before its first step reaches no node
    reference = stepped(stepper, T0, sources.dense(), forced, imposed, switched)
    assert np.isfinite(reference).all()
    rows = np.arange(0, n, 5)
    path, last = stepper.run(T0, sources, forced, imposed, switched, rows)
    scale = np.abs(reference).max()
    assert np.abs(path - reference[:, rows]).max() < 1e-11 * scale
    assert np.abs(last - reference[-1]).max() < 1e-11 * scale
    # a forced node is its imposed temperature exactly, as in the step
    assert np.array_equal(last[forced], imposed[-1, forced])


def test_without_a_compiler_the_run_steps_in_numpy(monkeypatch):
    network = assemble(load_building(TESTCELL))
    stepper = ImplicitEuler(network, 300.0)
    rng = np.random.default_rng(3)
    sources = Sources(*network.source_terms(10.0 + rng.normal(size=(200, len(network.input_names)))))
    forced = np.zeros(network.n_nodes, dtype=bool)
    T0 = np.full(network.n_nodes, 15.0)
    monkeypatch.setattr(compiled, "available", lambda: False)
    assert compiled.steps(stepper.matrix(forced), stepper.c_dt, sources, [], None, T0, [0]) is None
    path, last = stepper.run(T0, sources, forced, None, None, [0, 1])
    reference = stepped(stepper, T0, sources.dense(), forced, np.zeros((200, network.n_nodes)), None)
    assert np.array_equal(path, reference[:, :2]) and np.array_equal(last, reference[-1])


def test_a_singular_step_matrix_is_refused():
    # a node with no capacity and no link: its row of M is zero
    pattern = (np.array([0, 1, 2], dtype=np.int32), np.array([0, 1], dtype=np.int32))
    with pytest.raises(ValueError, match="singular"):
        compiled.steps((pattern, np.array([2.0, 0.0])), np.array([1.0, 0.0]), Sources(np.ones((3, 2)), np.eye(2), np.zeros(2)),
                       [], None, np.zeros(2), [0])


def test_a_compiler_that_fails_leaves_the_steps_to_numpy(monkeypatch, caplog):
    def fails(*args, **kwargs):
        raise RuntimeError("compiling 'steps.c' failed: cc: error: unrecognized option")
    monkeypatch.setattr(compiler, "built_library", fails)
    compiled._library.cache_clear()
    try:
        with caplog.at_level("WARNING", logger="nodeforce.model"):
            assert not compiled.available()
        assert "stepped in numpy: compiling 'steps.c' failed" in caplog.text
    finally:
        compiled._library.cache_clear()  # compiled again by the next test that runs steps
