"""The building file's own numerical error (model/numerical.py): the refined file is the same
building, node for node, and the error estimated against it vanishes where the nodal model is
exact (steady conduction) and falls as the file's own walls are refined."""
import numpy as np
import pandas as pd
import pytest

from nodeforce.model.building_file import load_building
from nodeforce.model.case import measured_case
from nodeforce.model.hlc import heat_loss_coefficient
from nodeforce.model.network import assemble
from nodeforce.model.numerical import discretisation_error, refined, share
from nodeforce.model.synth import pseudo_measurements
from tests.conftest import record_times

AIR = 23


@pytest.mark.parametrize("cells", [2, 4])
def test_the_refined_file_is_finer_and_has_the_files_conductances_and_capacities(cells):
    """Every cell of the refined file lies in one layer and in one of the file's cells and is at
    most 1/cells of it, but a window's gas gap, which keeps its two nodes (next test); each
    component's total resistance (sum of dx/lambda over its layers, by hand) and capacity (sum of
    rho c dx) are the file's; the file's nodes keep their ids and depths."""
    for path in ("model/data/testcell.json", "examples/twinhouse_n2/building.json"):
        building = load_building(path)
        fine = refined(building, cells)
        for c, f in zip(fine.components, building.components):
            assert dict(zip(f.node_ids, f.depths)).items() <= dict(zip(c.node_ids, c.depths)).items()
            bounds = np.cumsum([0.0] + [t for _, t in c.layers])
            gaps = [(bounds[g.layer], bounds[g.layer + 1]) for g in (c.window.gaps if c.window else ())]
            for a, b in zip(c.depths, c.depths[1:]):
                assert not np.any((bounds > a + 1e-12) & (bounds < b - 1e-12))  # no layer boundary inside
                if any(np.isclose(a, lo, atol=1e-12) and np.isclose(b, hi, atol=1e-12) for lo, hi in gaps):
                    continue
                k = np.searchsorted(f.depths, a, side="right") - 1
                assert b - a <= (f.depths[k + 1] - f.depths[k]) / cells + 1e-12
            by_hand_R = sum(t / m.conductivity for m, t in c.layers)
            by_hand_C = sum(t * m.density * m.specific_heat for m, t in c.layers)
            for b_ in (building, fine):
                n = assemble(b_)
                ids = np.array(b_.component(c.name).node_ids) - 1
                G = [n.A[i, j] for i, j in zip(ids, ids[1:])]
                assert sum(1 / g for g in G) * c.area == pytest.approx(by_hand_R, rel=1e-9)
                assert n.C[ids].sum() == pytest.approx(by_hand_C * c.area, rel=1e-9)
        assert heat_loss_coefficient(fine) == pytest.approx(heat_loss_coefficient(building), rel=1e-9)


def test_a_windows_gas_gap_keeps_its_two_face_nodes_in_the_refined_file():
    """A converted window's gaps (`Component.window`) need a node on each face and none within:
    the refined file keeps each gap's two nodes alone (their ids and depths the file's) while the
    panes beside it are cut into `cells` cells, and it parses as a building file."""
    building = load_building("examples/bestest/case600.json")
    windows = [c for c in building.components if c.window is not None]
    assert windows
    fine = refined(building, 4)
    for f in windows:
        c = fine.component(f.name)
        edges = np.cumsum([0.0] + [t for _, t in c.layers])
        depths = np.array(c.depths)
        for gap in c.window.gaps:
            lo, hi = edges[gap.layer], edges[gap.layer + 1]
            assert np.sum((depths >= lo - 1e-12) & (depths <= hi + 1e-12)) == 2
        assert len(c.depths) > len(f.depths)  # the panes are refined


def air_case(building, weather, days=5, past=30):
    """The test cell's air alone over `days` at 15 min in June, with `past` days of history."""
    measured = pseudo_measurements(building, weather, record_times(days), [AIR], history_days=past)
    return measured_case(building, weather, measured, burn_in_days=1)


def scored_error(case, building):
    e = discretisation_error(case, building, [AIR])[:, 0]
    return float(np.sqrt(np.mean(e[np.isfinite(case.scored([AIR - 1]))[:, 0]] ** 2)))


def test_steady_conduction_has_no_discretisation_error(testcell, weather):
    """Under constant weather, no sun and no heat input, a wall's temperature is piecewise linear
    within its layers and the file's conductances are exact integrals of dx/lambda: file and
    refined file reach the same steady state, so the estimate is the solvers' rounding."""
    steady = weather.copy()
    for column in steady.columns:
        steady[column] = steady[column].mean() if column in ("T_out", "T_sky", "T_ground") else 0.0
    steady.attrs = dict(weather.attrs)
    assert scored_error(air_case(testcell, steady), testcell) < 1e-8


def test_the_error_falls_as_the_files_walls_are_refined(testcell, weather):
    """Under June's sun the test cell's walls of one or two nodes per layer miss the continuum by
    hundredths of a degree; the same file with each of its cells halved misses it by less than
    half as much (the space discretisation is second order, the time step's first-order part the
    same in both)."""
    case = air_case(testcell, weather)
    coarse = scored_error(case, testcell)
    halved = refined(testcell, 2)
    finer = scored_error(measured_case(halved, weather, pd.DataFrame(
        {f"T{AIR}": case.measured[case.history_steps:, AIR - 1]}, index=case.times[case.history_steps:]),
        burn_in_days=1), halved)
    assert 0.01 < coarse < 0.2
    assert finer < 0.5 * coarse


def test_the_share_of_the_error_a_residual_holds_is_its_least_squares_coefficient_within_0_and_1():
    """A residual of -0.7 e plus a part orthogonal to e (a cosine against a sine over whole
    periods) holds 0.7 of e; twice the error is the continuum and more, 1; the error's opposite
    is no share of it, 0; on chosen rows, those rows' share; missing readings count for nothing."""
    t = np.linspace(0.0, 4 * np.pi, 400, endpoint=False)
    e = 0.05 * np.sin(t)
    assert share(-0.7 * e + 0.1 * np.cos(t), e) == pytest.approx(0.7, abs=1e-12)
    assert share(-2.0 * e, e) == 1.0
    assert share(0.5 * e, e) == 0.0
    halves = np.where(t < 2 * np.pi, -0.3 * e, -0.9 * e)
    assert share(halves, e, t >= 2 * np.pi) == pytest.approx(0.9, abs=1e-12)
    gappy = -0.4 * e
    gappy[::3] = np.nan
    assert share(gappy, e) == pytest.approx(0.4, abs=1e-12)
    assert share(gappy, np.zeros_like(e)) == 0.0


def test_the_model_a_candidate_is_measured_against_scores_each_day_with_the_share_the_other_days_hold():
    """Two records of four days each whose residual is -0.6 e on every day but one, which holds
    -0.2 e; e has the same energy E on every day. Each block is scored with the share fitted on
    all the others, as a candidate's left-out day is: the odd day with s = 0.6 (seven days of
    -0.6 e), leaving (0.6 - 0.2)^2 E; every other day with s = (6 x 0.6 + 0.2) / 7, leaving
    (0.6 - s)^2 E. Without the error given, every day keeps its whole residual, 0.36 E."""
    from nodeforce.diagnosis.policy import Policy
    from nodeforce.diagnosis.windows import RecordWindow, Windows

    day, days = 24, 4
    t = np.arange(day * days) / day
    e = (0.05 * np.sin(2 * np.pi * t) + 0.02)[:, None]
    masks = [(t // 1 == d) for d in range(days)]
    E = float(np.sum(e[masks[0]] ** 2))
    measured = [np.where(masks[2][:, None], -0.2 * e, -0.6 * e), -0.6 * e]  # minus a run of zeros: the residual
    runs = [np.zeros_like(e), np.zeros_like(e)]
    blocks = [(i, m) for i in range(2) for m in masks]

    def windows(numerical):
        return Windows([RecordWindow(None, None, len(t), None, m, [], None, e)
                        for m, e in zip(measured, numerical or [None] * 2)], blocks, Policy())
    s = (6 * 0.6 + 0.2) / 7
    odd = [i == 0 and m is masks[2] for i, m in blocks]
    expected = [(0.4 ** 2 if o else (0.6 - s) ** 2) * E for o in odd]
    np.testing.assert_allclose(windows([e, e]).block_J(runs), expected, rtol=1e-9)
    np.testing.assert_allclose(windows(None).block_J(runs), [(0.04 if o else 0.36) * E for o in odd], rtol=1e-9)
