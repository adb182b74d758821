"""Effects a diagnosis may add: declared in the building file, exposed as FMU parameters."""
import copy

import numpy as np
import pytest

from nodeforce.cosim.fmi import FmuInstance
from nodeforce.cosim.run import simulate_fmu
from nodeforce.fmu_build.build import build_fmu
from nodeforce.model import effects
from nodeforce.model.building import parse_building
from nodeforce.model.integrate import simulate
from nodeforce.model.network import assemble


def direct(data, case):
    b = parse_building(data)
    return simulate(b, assemble(b), case.U, case.dt, case.measured)


CASES = [
    ("ground_coupling", "floor", {"U": 0.8, "T_ground": 23.5}),
    ("infiltration", "cell", {"n": 1.0}),
    ("internal_gain", "cell", {"Q": 100.0}),
    ("solar_absorptance", "roof", {"alpha": 0.6}),
    ("conductivity", "door", {"factor": 3.4}),
    ("inside_convection", "cell", {"factor": 0.3}),
    ("solar_transmittance", "window", {"tau": 0.5}),
]


@pytest.mark.parametrize("effect,target,values", CASES, ids=[c[0] for c in CASES])
def test_fmu_parameters_equal_the_declared_effect(tmp_path, testcell_data, real_case, effect, target, values):
    fmu = build_fmu(testcell_data, tmp_path / "m.fmu", effect=(effect, target))
    parameters = {f"{effect}.{k}": v for k, v in values.items()}
    with FmuInstance(fmu) as instance:
        assert set(parameters) <= set(instance.names("parameter"))
        start = simulate_fmu(instance, real_case)
        changed = simulate_fmu(instance, real_case, parameters=parameters)
        again = simulate_fmu(instance, real_case)
    # at its start values the FMU is the building as declared; a reset forgets the parameters
    assert np.abs(start - direct(testcell_data, real_case)).max() < 1e-9
    assert np.array_equal(start, again)
    expected = direct(effects.apply(testcell_data, effect, target, values), real_case)
    assert np.abs(changed - expected).max() < 1e-9
    assert np.abs(changed - start).max() > 0.05  # the effect does something


def test_conductivity_factor_equals_scaling_the_materials(testcell_data, real_case):
    # the floor alone uses concrete, polystyrene and heavy concrete
    scaled = copy.deepcopy(testcell_data)
    for name in ("concrete", "polystyrene", "heavy_concrete"):
        scaled["materials"][name]["conductivity"] *= 2.5
    by_factor = effects.apply(testcell_data, "conductivity", "floor", {"factor": 2.5})
    assert np.abs(direct(by_factor, real_case) - direct(scaled, real_case)).max() < 1e-9


def test_convection_factor_equals_scaling_every_inside_coefficient(testcell_data, real_case):
    scaled = copy.deepcopy(testcell_data)
    for c in scaled["components"]:
        c["inside"]["h_conv"] *= 0.02
    by_factor = effects.apply(testcell_data, "inside_convection", "cell", {"factor": 0.02})
    assert np.abs(direct(by_factor, real_case) - direct(scaled, real_case)).max() < 1e-9


def test_ground_coupling_is_a_boundary_face(testcell_data):
    after = effects.apply(testcell_data, "ground_coupling", "floor", {"U": 0.5, "T_ground": 24.0})
    floor = next(c for c in after["components"] if c["name"] == "floor")
    assert floor["outside"] == {"type": "boundary", "temperature": 24.0, "h": 0.5}
    assert next(c for c in testcell_data["components"] if c["name"] == "floor")["outside"]["type"] == "adiabatic"
    assert effects.current_values(after, "ground_coupling", "floor") == {"U": 0.5, "T_ground": 24.0}
    # once coupled, the floor is no longer adiabatic: the effect cannot be added twice
    assert not effects.applicable(after, "ground_coupling", "floor")


def test_candidates_follow_the_located_nodes(testcell_data):
    air = [("infiltration", "cell"), ("internal_gain", "cell")]
    # node 17 is in the floor: adiabatic below, and it receives the window's sun
    assert effects.candidates(testcell_data, [17]) == [
        ("ground_coupling", "floor"), ("conductivity", "floor"), ("solar_transmittance", "window"), *air]
    assert effects.candidates(testcell_data, [9, 10]) == [
        ("solar_absorptance", "roof"), ("conductivity", "roof"), *air]
    assert effects.candidates(testcell_data, []) == [*air, ("inside_convection", "cell")]
