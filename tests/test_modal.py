"""Runs of steps under one step matrix, solved in their modes (`model.modal`), against the step
itself (`ImplicitEuler.step`, one step at a time) and a recurrence solved by hand."""
from pathlib import Path

import numpy as np
import pytest

from nodeforce.model import compiled, integrate, modal
from nodeforce.model.building_file import load_building
from nodeforce.model.integrate import ImplicitEuler, simulate
from nodeforce.model.network import assemble

ROOT = Path(__file__).parents[1]
TESTCELL = ROOT / "model" / "data" / "testcell.json"
HOUSE = ROOT / "examples" / "twinhouse_n2" / "building.json"


def stepped(stepper, network, T, U, forced, imposed):
    """Every node after each step, one `ImplicitEuler.step` at a time: the reference."""
    out = []
    for u, v in zip(network.sources(U), imposed):
        T = stepper.step(T, u, forced, v)
        out.append(T)
    return np.array(out)


def test_a_mode_s_scan_is_the_recurrence_solved_by_hand():
    # z^n+1 = lam z^n + w, w constant: z^n = lam^n z^0 + w (1 - lam^n) / (1 - lam)
    lam, z0, w = np.array([0.5, 0.9, 0.0]), np.array([4.0, -2.0, 7.0]), np.array([1.0, 3.0, -1.0])
    n = np.arange(1, 101)[:, None]
    expected = lam ** n * z0 + w * (1 - lam ** n) / (1 - lam)
    assert np.abs(modal.scan(lam, z0, np.tile(w, (100, 1))) - expected).max() < 1e-12


@pytest.mark.parametrize("path, forced_ids", [(TESTCELL, ()), (TESTCELL, (1, 7, 9, 16, 17, 23))],
                         ids=["test cell", "test cell, the paper's sensors forced"])
def test_a_run_in_modes_is_the_steps_to_rounding(path, forced_ids):
    building = load_building(path)
    network = assemble(building)
    n = network.n_nodes
    stepper = ImplicitEuler(network, 300.0)
    rng = np.random.default_rng(1)
    L = 2000
    U = 10.0 + 5.0 * rng.normal(size=(L, len(network.input_names)))
    forced = np.zeros(n, dtype=bool)
    forced[[i - 1 for i in forced_ids]] = True
    imposed = 20.0 + rng.normal(size=(L, n))
    T0 = np.linspace(10.0, 30.0, n)
    reference = stepped(stepper, network, T0, U, forced, imposed)
    solve, _ = stepper.solver(forced)
    modes = stepper.modes(forced)
    assert modes is not None
    outputs = np.arange(0, n, 3)
    kept = np.arange(5, L, 7)
    T, last = modal.run(solve.inverse, stepper.c_dt, forced, modes, T0, *network.source_terms(U), imposed, kept,
                        outputs)
    scale = np.abs(reference).max()
    assert np.abs(T - reference[np.ix_(kept, outputs)]).max() < 1e-12 * scale
    assert np.abs(last - reference[-1]).max() < 1e-12 * scale
    # a forced node is its imposed temperature exactly, as in the step
    for i in np.flatnonzero(forced[outputs]):
        assert np.array_equal(T[:, i], imposed[kept, outputs[i]])


def test_a_network_with_air_carried_one_way_is_stepped():
    """The Twin House's supply carries air from room to room: its step matrix is not similar to
    a symmetric one, and its runs are stepped; a symmetric one's modes rebuild G."""
    network = assemble(load_building(HOUSE))
    assert not np.allclose(network.A, network.A.T)
    stepper = ImplicitEuler(network, 300.0)
    assert stepper.modes(np.zeros(network.n_nodes, dtype=bool)) is None
    # which masks have modes, told from M's one-way pairs before any inverse is formed, is what
    # the modes of the inverse say: air carried between two forced zones leaves the rest symmetric
    building = load_building(HOUSE)
    air = np.zeros(network.n_nodes, dtype=bool)
    air[[z.air_node - 1 for z in building.zones]] = True
    masks = [air, np.random.default_rng(4).random(network.n_nodes) < 0.5]
    for mask in masks:
        solve = integrate.DenseSolve(integrate.unit_rows(np.diag(stepper.c_dt) - network.A, mask))
        of = modal.Modes.of(solve.inverse, stepper.c_dt, mask)
        found = ImplicitEuler(network, 300.0).modes(mask)
        assert (found is None) == (of is None)
    assert ImplicitEuler(network, 300.0).modes(air) is not None
    cell = ImplicitEuler(assemble(load_building(TESTCELL)), 300.0)
    free = np.zeros(cell.network.n_nodes, dtype=bool)
    modes, (solve, _) = cell.modes(free), cell.solver(free)
    G = solve.inverse[np.ix_(modes.state, modes.state)] * modes.c_x[None, :]
    assert np.abs((modes.V * modes.lam) @ modes.V_inv - G).max() < 1e-12 * np.abs(G).max()


def test_a_record_with_gaps_and_a_burn_in_is_simulated_as_stepped(testcell, real_case, monkeypatch):
    """The forcing mask changes after the burn-in and wherever a forced node's measurement is
    missing: each run between changes in its modes or stepped, the whole equals the record
    stepped one step at a time, and the nodes asked for are those columns. (Runs go to their
    modes where the steps are numpy's.)"""
    monkeypatch.setattr(compiled, "available", lambda: False)
    network = assemble(testcell)
    measured = real_case.measured.copy()
    measured[200:230, 6] = np.nan  # a gap in the door's surface, forced
    force = np.zeros(network.n_nodes, dtype=bool)
    force[6] = True
    kwargs = dict(measured=measured, force=force, burn_in_steps=96, substeps=real_case.substeps, warmup_days=1)
    runs = []
    monkeypatch.setattr(integrate, "modal_run", lambda *args: runs.append(len(args[5])) or modal.run(*args))
    in_modes = simulate(testcell, network, real_case.U, real_case.dt, **kwargs)
    assert len(runs) >= 2  # the burn-in and the runs between the gaps, in modes
    outputs = simulate(testcell, network, real_case.U, real_case.dt, outputs=[22, 3], **kwargs)
    monkeypatch.setattr(integrate, "MODAL_FROM", 10 ** 9)  # every run stepped
    reference = simulate(testcell, network, real_case.U, real_case.dt, **kwargs)
    assert np.abs(in_modes - reference).max() < 1e-10
    assert np.abs(outputs - reference[:, [22, 3]]).max() < 1e-10
    assert np.ptp(reference[:, 22]) > 1.0  # the air moves: the comparison is of something
