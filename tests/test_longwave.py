"""The zones' long-wave exchange by ScriptF (model/longwave.py, docs/model.md section 3.5) against
hand calculations, conservation, a limit and the radiosity network solved independently; in the
network, the direct model, the compiled steps and the Python FMU."""
import copy

import numpy as np
import pytest

from nodeforce.api import convert_idf
from nodeforce.cosim.fmi import FmuInstance
from nodeforce.cosim.run import simulate_fmu
from nodeforce.fmu_build.build import build_fmu
from nodeforce.model import compiled
from nodeforce.model.building_file import parse_building
from nodeforce.model.errors import InputError
from nodeforce.model.integrate import simulate
from nodeforce.model.longwave import SIGMA, T_MEAN, approximate_view_factors, fix_view_factors, script_f
from nodeforce.model.network import assemble, input_names

from .test_energyplus import CASE600

H_LINEAR = 4.0 * SIGMA * T_MEAN ** 3  # W/m2/K


def test_two_large_parallel_plates():
    """Each plate sees only the other: q = sigma (T1^4 - T2^4) / (1/e1 + 1/e2 - 1) per m2."""
    e1, e2 = 0.9, 0.6
    SF = script_f([1.0, 1.0], [[0.0, 1.0], [1.0, 0.0]], [e1, e2])
    assert SF[0, 1] == pytest.approx(1.0 / (1.0 / e1 + 1.0 / e2 - 1.0), rel=1e-12)
    assert SF[1, 0] == pytest.approx(SF[0, 1], rel=1e-12)


CUBE_TILTS = (90.0, 90.0, 90.0, 90.0, 0.0, 180.0)
CUBE_AZIMUTHS = (0.0, 90.0, 180.0, 270.0, 0.0, 0.0)
CUBE_CLASSES = ("wall", "wall", "wall", "wall", "roof", "floor")


def test_a_cube_of_equal_faces():
    """Six faces of one emissivity e, each seeing each other by 1/5. Face j alone emitting, its
    radiosity a and the others' b solve a = e + (1 - e) b and b = (1 - e) (a + 4 b) / 5; each
    other face absorbs e b / (1 - e) = e^2 / (5 - 4 (1 - e) - (1 - e)^2) of j's emission."""
    A = np.full(6, 9.0)
    F = fix_view_factors(A, approximate_view_factors(A, CUBE_TILTS, CUBE_AZIMUTHS, CUBE_CLASSES))
    assert F == pytest.approx(np.where(np.eye(6, dtype=bool), 0.0, 0.2), abs=1e-12)
    e = 0.9
    SF = script_f(A, F, np.full(6, e))
    expected = e ** 2 / (5.0 - 4.0 * (1.0 - e) - (1.0 - e) ** 2)
    assert SF[~np.eye(6, dtype=bool)] == pytest.approx(np.full(30, expected), rel=1e-12)


@pytest.fixture(scope="module")
def case600():
    return convert_idf(CASE600)


@pytest.fixture(scope="module")
def enclosure(case600):
    """Case 600's eight faces: areas, emissivities (0.84 the windows') and view factors."""
    names, _, A, eps, tilts, azimuths, classes = case600.enclosure("CASE 600 ZONE")
    A, eps = np.array(A), np.array(eps)
    F = fix_view_factors(A, approximate_view_factors(A, tilts, azimuths, classes))
    return names, A, eps, F


def test_fixed_view_factors_are_reciprocal_and_complete(case600, enclosure):
    """The approximation is not reciprocal (A_i A_j over what each face sees, which differs from
    face to face); the fix makes A F symmetric, its rows summing to 1."""
    names, A, _, F = enclosure
    _, _, _, _, tilts, azimuths, classes = case600.enclosure("CASE 600 ZONE")
    raw = A[:, None] * approximate_view_factors(A, tilts, azimuths, classes)
    assert np.abs(raw - raw.T).max() > 0.1
    assert F.sum(axis=1) == pytest.approx(np.ones(8), abs=1e-3)
    assert A[:, None] * F == pytest.approx((A[:, None] * F).T, rel=1e-12)
    # the windows and the south wall face one way: they do not see each other
    assert F[names.index("SOUTH WALL"), names.index("SOUTH WINDOW WEST")] == 0.0


def test_script_f_is_reciprocal_and_conserves_energy(enclosure):
    """A_i SF_ij = A_j SF_ji; at one temperature everywhere no face gains (sum_j SF_ij = e_i:
    each absorbs e_i of the black-body radiation that fills an isothermal enclosure); and the
    nonlinear exchange at any temperatures sums to zero."""
    _, A, eps, F = enclosure
    SF = script_f(A, F, eps)
    assert A[:, None] * SF == pytest.approx((A[:, None] * SF).T, rel=1e-9)
    assert SF.sum(axis=1) == pytest.approx(eps, rel=1e-3)  # F complete to FixViewFactors' 0.001
    T4 = (273.15 + np.random.default_rng(1).uniform(-5.0, 40.0, len(A))) ** 4
    gained = A * (SIGMA * SF @ T4 - SIGMA * SF.sum(axis=1) * T4)
    assert abs(gained.sum()) < 1e-9 * np.abs(gained).max()


def test_black_faces_exchange_by_their_view_factors(enclosure):
    """All emissivities 1: nothing is reflected, and ScriptF is F."""
    _, A, _, F = enclosure
    SF = script_f(A, F, np.ones(len(A)))
    assert SF == pytest.approx(F, abs=1e-4)  # EnergyPlus's emissivities at most 0.99999


def test_script_f_is_the_radiosity_network_solved(enclosure):
    """Oppenheim's network, solved for the radiosities J directly: what reaches each face's
    radiosity through its surface resistance (1 - e)/(e A) from E = sigma T^4 leaves it to the
    others, A_i (J_i - sum_j F_ij J_j); the net heat each face loses, (E - J) e A / (1 - e), is
    what it emits less what ScriptF says it absorbs, A_i (e_i E_i - sum_j SF_ij E_j)."""
    _, A, eps, F = enclosure
    E = SIGMA * (273.15 + np.random.default_rng(2).uniform(0.0, 30.0, len(A))) ** 4
    surface = eps * A / (1.0 - eps)
    K = np.diag(surface + A) - A[:, None] * F
    J = np.linalg.solve(K, surface * E)
    lost = surface * (E - J)
    SF = script_f(A, F, eps)
    assert A * (eps * E - SF @ E) == pytest.approx(lost, rel=1e-9, abs=1e-9)


# ---- in the network ---------------------------------------------------------------------------
def scriptf(data, **zone):
    data = copy.deepcopy(data)
    data["zones"][0].update({"longwave": "scriptf", **zone})
    return parse_building(data)


def test_faces_are_linked_pairwise_and_the_radiant_node_is_their_mean(testcell_data):
    b = scriptf(testcell_data, heat_input="P", heat_input_radiative_fraction=0.4)
    net = assemble(b)
    names, ids, A, eps, tilts, azimuths, classes = b.enclosure("cell")
    SF = script_f(np.array(A), fix_view_factors(np.array(A), approximate_view_factors(A, tilts, azimuths, classes)),
                  eps)
    i, j = names.index("roof"), names.index("floor")
    # the roof and the floor: A_i SF_ij 4 sigma T_m^3, and nothing through the radiant node
    assert net.A[ids[i] - 1, ids[j] - 1] == pytest.approx(A[i] * SF[i, j] * H_LINEAR, rel=1e-9)
    radiant, air = b.zones[0].radiant_node - 1, b.zones[0].air_node - 1
    assert np.all(net.A[:, radiant][np.arange(net.n_nodes) != radiant] == 0.0)
    # the radiant part of the heat input goes to the faces by A eps: the test cell's are all 0.9
    column = input_names(b).index("P")
    assert net.B[air, column] == pytest.approx(0.6)
    assert net.B[np.array(ids) - 1, column] == pytest.approx(0.4 * np.array(A) / sum(A), rel=1e-12)
    assert net.B[radiant, column] == 0.0
    # at any temperatures the radiant node's row reads the faces' mean radiant temperature
    T = np.random.default_rng(3).uniform(10.0, 30.0, net.n_nodes)
    T[radiant] = np.dot(A, T[np.array(ids) - 1]) / sum(A)
    assert net.A[radiant] @ T == pytest.approx(0.0, abs=1e-9)


def test_a_file_without_the_option_keeps_its_radiant_node(testcell_data, testcell):
    declared = copy.deepcopy(testcell_data)
    declared["zones"][0]["longwave"] = "radiant_node"
    a, b = assemble(testcell), assemble(parse_building(declared))
    assert np.array_equal(a.A, b.A) and np.array_equal(a.B, b.B) and np.array_equal(a.q, b.q)


def test_declared_view_factors_replace_the_approximation(testcell_data):
    """The roof and the floor declared to see only each other are two parallel plates of 9 m2
    (the fix leaves declared factors that cannot be made complete as they are); the door sees
    nothing."""
    b = scriptf(testcell_data, view_factors={"roof": {"floor": 1.0}, "floor": {"roof": 1.0}})
    net = assemble(b)
    names, ids, *_ = b.enclosure("cell")
    roof, floor, door = (ids[names.index(n)] - 1 for n in ("roof", "floor", "door"))
    e = 0.9
    # two parallel plates of 9 m2
    assert net.A[roof, floor] == pytest.approx(9.0 / (2.0 / e - 1.0) * H_LINEAR, rel=1e-9)
    assert net.A[roof, door] == 0.0


@pytest.mark.parametrize("zone, problem", [
    ({"view_factors": {"roof": {"floor": 1.0}}, "longwave": "radiant_node"}, "only with longwave"),
    ({"view_factors": {"roof": {"attic": 1.0}}}, "is no face of zone"),
    ({"view_factors": {"roof": {"floor": 0.7, "door": 0.5}}}, "add up to 1.2"),
])
def test_bad_view_factors_are_refused_naming_the_field(testcell_data, zone, problem):
    with pytest.raises(InputError, match=problem) as error:
        scriptf(testcell_data, **zone)
    assert "zones[0].view_factors" in str(error.value)


@pytest.fixture(scope="module")
def scriptf_cell(testcell_data):
    return scriptf(testcell_data)


def test_the_direct_model_and_the_python_fmu_agree(scriptf_cell, testcell, real_case, tmp_path):
    net = assemble(scriptf_cell)
    direct = simulate(scriptf_cell, net, real_case.U, real_case.dt, real_case.measured, substeps=real_case.substeps)
    with FmuInstance(build_fmu(scriptf_cell, tmp_path / "scriptf.fmu")) as instance:
        through_fmu = simulate_fmu(instance, real_case)
    assert np.abs(through_fmu - direct).max() < 1e-9
    assert np.ptp(direct[:, 22]) > 2.0  # the air swings with the weather
    # and the air differs from the star node's: the option acts
    star = simulate(testcell, assemble(testcell), real_case.U, real_case.dt, real_case.measured,
                    substeps=real_case.substeps)
    assert np.abs(star[:, 22] - direct[:, 22]).max() > 0.01


@pytest.mark.skipif(not compiled.available(), reason="no C compiler: the steps are numpy's")
def test_compiled_steps_are_the_steps(scriptf_cell):
    from nodeforce.model.integrate import ImplicitEuler, Sources
    network = assemble(scriptf_cell)
    n, L = network.n_nodes, 400
    rng = np.random.default_rng(4)
    sources = Sources(*network.source_terms(10.0 + 5.0 * rng.normal(size=(L, len(network.input_names)))))
    stepper = ImplicitEuler(network, 300.0)
    forced = np.zeros(n, dtype=bool)
    imposed = np.full((L, n), np.nan)
    T = np.linspace(10.0, 30.0, n)
    reference = []
    for source, T_forced in zip(sources.dense(), imposed):
        T = stepper.step(T, source, forced, T_forced, None)
        reference.append(T)
    path, last = stepper.run(np.linspace(10.0, 30.0, n), sources, forced, imposed, None, np.arange(n))
    assert np.abs(np.array(reference) - path).max() < 1e-9 and np.abs(reference[-1] - last).max() < 1e-9


def test_forcing_the_mean_radiant_temperature_is_refused(scriptf_cell, real_case):
    from nodeforce.ga.locate import chromosome_nodes
    from nodeforce.model.score import Objective
    radiant = scriptf_cell.zones[0].radiant_node
    with pytest.raises(InputError, match="read by no other node"):
        chromosome_nodes(scriptf_cell, real_case, Objective.of(scriptf_cell), "test", nodes=[radiant])


def test_a_run_in_modes_is_the_steps(scriptf_cell):
    """The radiant node's one-way row (it reads the faces, none reads it) leaves the state's step
    symmetric: the run is solved in its modes, and its temperatures, the radiant node's
    included, are the steps'."""
    from nodeforce.model import modal
    from nodeforce.model.integrate import ImplicitEuler
    network = assemble(scriptf_cell)
    n, L = network.n_nodes, 1000
    stepper = ImplicitEuler(network, 300.0)
    forced = np.zeros(n, dtype=bool)
    modes = stepper.modes(forced)
    assert modes is not None
    U = 10.0 + 5.0 * np.random.default_rng(5).normal(size=(L, len(network.input_names)))
    imposed = np.full((L, n), np.nan)
    T0 = np.linspace(10.0, 30.0, n)
    reference, T = [], T0
    for u, v in zip(network.sources(U), imposed):
        T = stepper.step(T, u, forced, v)
        reference.append(T)
    solve, _ = stepper.solver(forced)
    kept, outputs = np.arange(L), np.arange(n)
    path, last = modal.run(solve.inverse, stepper.c_dt, forced, modes, T0, *network.source_terms(U), imposed, kept,
                           outputs)
    assert np.abs(path - np.array(reference)).max() < 1e-10 * np.abs(reference).max()
