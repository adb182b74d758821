"""The temperatures' derivatives with respect to an effect's parameters (forward sensitivities,
`integrate.simulate(derivatives=...)`, docs/model.md section 5.9) against central differences
of runs, for every effect of the registry, on a network whose runs are solved in their modes
(the test cell, stepped in numpy: where the steps are compiled no run goes to its modes) and on
one stepped in C where a compiler is found (two zones, air carried one way, a switched
ventilation);
a parameter the network is not affine in keeps differences of runs; the derivative of the share
of the numerical error."""
import numpy as np
import pandas as pd
import pytest

from nodeforce.diagnosis.calibrate import AFFINE, Candidate
from nodeforce.diagnosis.candidates import calibration_start
from nodeforce.model import compiled
from nodeforce.model.building_file import load_building, parse_building
from nodeforce.model.case import Case
from nodeforce.model.effects import EFFECTS, Effect, Parameter
from nodeforce.model.integrate import simulate
from nodeforce.model.network import assemble, derivative, switched_matrix
from nodeforce.model.numerical import share, share_slope

from .conftest import DATA
from .test_house_effects import with_all
from .test_zones import multizone_with_everything

DT, DAYS, HISTORY = 900.0, 4, 24  # s, days of record, samples of history (two of its 3-h steps)
# central differences of a relative step of 1e-4 are exact to some 1e-8 here (their truncation
# and rounding); the derivatives must agree with them to
RTOL = 1e-6


def house():
    """Two zones with every house effect's target, a ground face and a ventilation switched by a
    schedule (its conductance follows the schedule: `Network.switched`)."""
    data = with_all(multizone_with_everything()).to_json()
    data["components"].append(
        {"name": "slab", "area": 10.0, "tilt": 180.0, "azimuth": 0.0, "layers": [["board", 0.15]],
         "nodes": {"max_spacing": 0.05}, "inside": {"zone": "B", "h_conv": 2.0, "h_rad": 5.0},
         "outside": {"type": "adiabatic"}})
    data["schedules"] = {"night": {"days": {"d": [[6, 1.0], [18, 0.25], [24, 1.0]]},
                                   "periods": [{"through": "12-31", "week": ["d"] * 7}]}}
    data["zones"][1]["ventilation"] = [{"name": "vent", "flow": 40.0, "schedule": "night"}]
    return parse_building(data)


def record(building, seed):
    """A case as a diagnosis runs one: a history, a steady start, a burn-in forcing the measured
    nodes, sub-steps; the weather and heat inputs made up, the air and a surface measured."""
    rng = np.random.default_rng(seed)
    n_rows = HISTORY + DAYS * 96 + 1
    times = pd.date_range("2014-04-09", periods=n_rows, freq="15min", tz="+01:00", name="time")
    hours = np.arange(n_rows) * 0.25
    day = np.sin(2 * np.pi * hours / 24)
    columns = {"T_out": 8 + 6 * day + rng.normal(0, 0.3, n_rows), "T_sky": -2 + 6 * day,
               "heater": rng.choice([0.0, 900.0], n_rows), "duct": np.full(n_rows, -60.0),
               "T_supply": 17 + 3 * np.cos(2 * np.pi * hours / 24),
               "T_cellar": 13 + 0.5 * np.sin(2 * np.pi * hours / 72), "blind": (day > 0.5).astype(float)}
    for c in building.exterior_components:
        columns[c.irradiance_input] = np.clip(600 * day, 0, None)
    measured = np.full((n_rows, building.n_nodes), np.nan)
    for z in building.zones[:1]:
        measured[HISTORY:, z.air_node - 1] = 21 + day[HISTORY:] + rng.normal(0, 0.1, n_rows - HISTORY)
    face = building.components[0].node_ids[0] - 1
    measured[HISTORY:, face] = 20 + 0.5 * day[HISTORY:]
    case = Case(times, DT, tuple(columns), np.column_stack(list(columns.values())), measured,
                burn_in_steps=HISTORY + 96, steady_start=True, substeps=3, history_steps=HISTORY, building=building)
    return case.with_inputs(building)


def buildings():
    return {"test cell": load_building(DATA / "testcell_miami.json"), "house": house()}


def effect_cases():
    out = []
    for label, building in buildings().items():
        for effect, record_ in EFFECTS.items():
            targets = record_.targets(building)
            if targets:
                out.append((label, effect, targets[0]))
    return out


CASES = effect_cases()


def runs(building, effect, target, case, values, outputs, force=None, derivatives=()):
    changed = EFFECTS[effect].apply(building, target, dict(zip([p.name for p in EFFECTS[effect].parameters], values)))
    network = assemble(changed)
    return simulate(changed, network, case.U, case.dt, case.measured, force=force, burn_in_steps=case.burn_in_steps,
                    steady_start=case.steady_start, substeps=case.substeps, history_steps=case.history_steps,
                    outputs=outputs, derivatives=derivatives), network


@pytest.mark.parametrize("label, effect, target", CASES, ids=[f"{e}@{t} ({b})" for b, e, t in CASES])
def test_the_derivatives_of_every_effect_equal_central_differences(label, effect, target, monkeypatch):
    if label == "test cell":
        monkeypatch.setattr(compiled, "available", lambda: False)
    building = buildings()[label]
    record_ = EFFECTS[effect]
    base = record_.apply(building, target, {})  # the building reading the inputs the effect reads
    case = record(base, seed=1)
    start = calibration_start(building, effect, target)
    x = np.array([start[p.name] for p in record_.parameters], dtype=float)
    bounds = record_.bounds(building, target)
    outputs = np.arange(base.n_nodes)
    # a node forced over part of the record too (the search's Dirichlet condition)
    force = np.zeros(base.n_nodes, dtype=bool)
    force[base.components[0].node_ids[0] - 1] = True
    _, network = runs(building, effect, target, case, x, outputs)

    def at(values):
        return assemble(record_.apply(building, target, dict(zip([p.name for p in record_.parameters], values))))

    derivatives, affine = [], []
    for i, (low, high) in enumerate(bounds):
        step = np.zeros_like(x)
        step[i] = 0.01 * (high - low)
        one, two = derivative(network, at(x + step), step[i]), derivative(at(x + step), at(x + 2 * step), step[i])
        if one is not None and two is not None and one.close_to(two, AFFINE):
            derivatives.append(one)
            affine.append(i)
    # a network curved in a parameter keeps differences of runs (`Candidate.jacobian`): the
    # internal mass's face, whose area H_m sets, in the zone's ScriptF and the sun's split
    assert len(affine) == len(bounds) - (effect == "internal_mass"), (effect, affine)
    for forcing in (None, force):
        plain, _ = runs(building, effect, target, case, x, outputs, forcing)
        (T, dT), _ = runs(building, effect, target, case, x, outputs, forcing, derivatives)
        # the temperatures are the run's own (a run in modes forms more of them: to rounding)
        assert np.abs(T - plain).max() <= 1e-12 * np.abs(plain).max()
        for j, i in enumerate(affine):
            low, high = bounds[i]
            h = 1e-4 * max(abs(x[i]), 1e-3 * (high - low))
            up, down = x.copy(), x.copy()
            up[i] += h
            down[i] -= h
            central = (runs(building, effect, target, case, up, outputs, forcing)[0]
                       - runs(building, effect, target, case, down, outputs, forcing)[0]) / (2 * h)
            scale = np.abs(central).max()
            assert scale > 0.0, "the parameter moves no temperature: nothing checked"
            assert np.abs(dT[..., j] - central).max() <= RTOL * scale, (effect, record_.parameters[i].name)


@pytest.mark.parametrize("label, effect, target", CASES, ids=[f"{e}@{t} ({b})" for b, e, t in CASES])
def test_a_candidate_s_network_moved_along_its_derivatives_is_the_one_assembled(label, effect, target):
    """A candidate's network at values across its ranges, moved from the start's along its
    derivatives, against the building edited and assembled there: every coefficient the same to
    1e-9 of what the move changed, and the same links, products and switched conductances. The
    ground coupling's q holds U T_ground, affine in each parameter alone but not in both, and the
    internal mass's face enters the zone's ScriptF and the sun's split by its area H_m / h_m:
    neither has an affine network, and each is assembled at each value."""
    building = buildings()[label]
    candidate = Candidate(building, effect, target)
    affine = candidate.affine(building)
    if effect in ("ground_coupling", "internal_mass"):  # the mass's face curved in H_m
        assert affine is None
        return
    assert affine is not None
    start = assemble(candidate.built(affine.at))
    rng = np.random.default_rng(3)
    for _ in range(3):
        x = np.array([rng.uniform(low, high) for low, high in candidate.bounds])
        assembled, got = assemble(candidate.built(x)), affine.network_at(x)
        assert [p[:3] for p in got.products] == [p[:3] for p in assembled.products]
        assert [s[:2] for s in got.switched] == [s[:2] for s in assembled.switched]
        for coefficients in (lambda n: n.C, lambda n: n.A, lambda n: n.B, lambda n: n.q,
                             lambda n: n.source_coefficients, switched_matrix):
            change = np.abs(coefficients(assembled) - coefficients(start)).max(initial=0.0)
            assert np.abs(coefficients(got) - coefficients(assembled)).max(initial=0.0) <= 1e-9 * change
        moved = np.abs(assembled.A - start.A).max() + np.abs(assembled.source_coefficients - start.source_coefficients).max()
        assert moved + np.abs(assembled.C - start.C).max() + np.abs(assembled.q - start.q).max() > 0.0


def test_a_parameter_the_network_is_not_affine_in_keeps_differences_of_runs(monkeypatch, testcell, caplog):
    """An effect whose conductivity factor is the square of its parameter: the network's two
    steps' differences disagree, the column is least squares' own forward difference of runs,
    and the log says so; an affine one's column is the sensitivities' (they differ by that
    difference's error)."""
    square = Effect("squared_conductivity", "a conductivity factor p^2", (Parameter("p", "-", 0.5, 3.0),),
                    lambda b: [c.name for c in b.components],
                    lambda b, t: {"p": float(np.sqrt(b.component(t).conductivity_factor))},
                    lambda data, t, v: next(c for c in data["components"] if c["name"] == t).update(
                        conductivity_factor=float(v["p"]) ** 2),
                    lambda b, t: b.component(t).node_ids)
    monkeypatch.setitem(EFFECTS, square.id, square)
    case = record(testcell, seed=2)
    ids = [testcell.zones[0].air_node]
    caplog.set_level("INFO", logger="nodeforce.diagnosis")
    squared = Candidate(testcell, "squared_conductivity", "door")
    J = squared.jacobian(case, ids, [1.3])
    assert "not affine in p" in caplog.text
    h = np.sqrt(np.finfo(float).eps) * 1.3
    forward = (squared.nodes(case, ids, [1.3 + h]) - squared.nodes(case, ids, [1.3])) / h
    assert np.array_equal(J[..., 0], forward)
    # the same physics by the registry's affine factor f = p^2: dT/dp = 2 p dT/df, propagated exactly;
    # the forward difference agrees to its own error (its step's rounding: 1e-5 of the largest here)
    affine = Candidate(testcell, "conductivity", "door").jacobian(case, ids, [1.3 ** 2])[..., 0] * 2 * 1.3
    assert np.abs(J[..., 0] - affine).max() <= 1e-4 * np.abs(affine).max()
    assert not np.array_equal(J[..., 0], affine)


def test_the_share_s_derivative_is_its_difference_quotient_inside_and_zero_where_clipped():
    rng = np.random.default_rng(5)
    error = rng.normal(0.0, 0.2, 300)
    slopes = rng.normal(0.0, 1.0, (300, 2))

    def residual(x):
        return -0.4 * error + 0.05 * rng_free + slopes @ x
    rng_free = np.random.default_rng(6).normal(0.0, 1.0, 300)
    x, h = np.array([0.01, -0.02]), 1e-6
    assert 0.0 < share(residual(x), error) < 1.0
    numeric = [(share(residual(x + h * e), error) - share(residual(x - h * e), error)) / (2 * h) for e in np.eye(2)]
    np.testing.assert_allclose(share_slope(residual(x), error, None, slopes), numeric, rtol=1e-6)
    clipped = residual(x) + 5.0 * error  # the residual holds more than all of the error: s held at 0
    assert share(clipped, error) == 0.0
    assert not share_slope(clipped, error, None, slopes).any()



def test_a_derivative_s_source_on_some_nodes_is_the_dense_formula_s_there():
    """`Derivative.source` forms the right-hand side of the derivatives' steps on the nodes it is
    given from the blocks its coefficients move: on random coefficients, every term nonzero
    (switched conductances too, which no effect of the registry moves yet), it is the dense
    (C/dt)(T^n - T^n+1) + q + A T^n+1 + B' terms - (G u) T^n+1 on those columns."""
    from nodeforce.model.network import Coefficients, Derivative

    rng = np.random.default_rng(5)
    n, k, m, steps, dt = 9, 4, 3, 6, 600.0

    def sparse(shape, rows, cols):
        M = np.zeros(shape)
        M[np.ix_(rows, cols)] = rng.normal(size=(len(rows), len(cols)))
        return M

    C, q = np.zeros(n), np.zeros(n)
    C[[1, 6]], q[[2]] = rng.normal(size=2), rng.normal()
    A, B, G = sparse((n, n), [1, 2], [1, 2, 7]), sparse((n, k), [6], [0, 3]), sparse((n, m), [2, 8], [1])
    d = Derivative(C=C, A=Coefficients(A), B=Coefficients(B), q=q, G=Coefficients(G))
    before, after = rng.normal(size=(steps, n)), rng.normal(size=(steps, n))
    terms, inputs = rng.normal(size=(steps, k)), rng.normal(size=(steps, m))
    dense = (before - after) * (C / dt) + q + after @ A.T + terms @ B.T - (inputs @ G.T) * after
    nodes = np.array([1, 2, 4, 6, 7, 8])  # the rows the source may be nonzero on, and one beside them
    assert set(d.rows) <= set(nodes)
    np.testing.assert_allclose(d.source(before, after, terms, inputs, dt, nodes), dense[:, nodes],
                               rtol=1e-12, atol=1e-12)
