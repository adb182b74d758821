"""Effects a diagnosis may add: declared in the building file, exposed as FMU parameters."""
import copy

import numpy as np
import pytest

from nodeforce.cosim.fmi import FmuInstance
from nodeforce.cosim.run import simulate_fmu
from nodeforce.fmu_build.build import build_fmu
from nodeforce.diagnosis.candidates import physical
from nodeforce.diagnosis.policy import Policy
from nodeforce.model.building import Boundary
from nodeforce.model.building_file import parse_building
from nodeforce.model.effects import EFFECTS
from nodeforce.model.errors import InputError
from nodeforce.model.integrate import simulate
from nodeforce.model.network import assemble


def direct(b, case):
    return simulate(b, assemble(b), case.U, case.dt, case.measured, substeps=case.substeps)


CASES = [
    ("ground_coupling", "floor", {"U": 0.8, "T_ground": 23.5}),
    ("infiltration", "cell", {"n": 1.0}),
    ("internal_gain", "cell", {"Q": 100.0}),
    ("solar_absorptance", "roof", {"alpha": 0.6}),
    ("conductivity", "door", {"factor": 3.4}),
    ("inside_convection", "cell", {"factor": 0.3}),
    ("solar_transmittance", "window", {"tau": 0.5}),
    ("thermal_bridge", "cell", {"UA": 4.0}),
    ("daily_gain", "cell", {"mean": 30.0, "cos1": -60.0, "sin1": -20.0, "cos2": 10.0, "sin2": 15.0,
                            "cos3": 5.0, "sin3": -8.0, "cos4": 3.0, "sin4": 2.0}),
    ("workday_gain", "cell", {"mean": 90.0, "cos1": -80.0, "sin1": -30.0, "cos2": 10.0, "sin2": 15.0,
                              "cos3": 5.0, "sin3": -8.0, "cos4": 3.0, "sin4": 2.0}),
    ("proportional_gain", "cell->I_window", {"k": 0.5}),
    ("internal_mass", "cell", {"C_m": 3e5, "H_m": 40.0}),
    ("envelope_conductance", "cell", {"factor": 1.8}),
]


@pytest.mark.parametrize("effect,target,values", CASES, ids=[c[0] for c in CASES])
def test_fmu_parameters_equal_the_declared_effect(tmp_path, testcell, real_case, effect, target, values):
    fmu = build_fmu(testcell, tmp_path / "m.fmu", effect=(effect, target))
    # the inputs of the building with the effect declared (a daily gain adds the time of day)
    case = real_case.with_inputs(EFFECTS[effect].apply(testcell, target, {}))
    parameters = {f"{effect}.{k}": v for k, v in values.items()}
    with FmuInstance(fmu) as instance:
        assert set(parameters) <= set(instance.names("parameter"))
        start = simulate_fmu(instance, case)
        changed = simulate_fmu(instance, case, parameters=parameters)
        again = simulate_fmu(instance, case)
    # at its start values the FMU is the building as declared; a reset forgets the parameters
    assert np.abs(start - direct(testcell, real_case)).max() < 1e-9
    assert np.array_equal(start, again)
    # the building's own nodes (those a zone effect adds are not in the case's outputs)
    expected = direct(EFFECTS[effect].apply(testcell, target, values), case)[:, :testcell.n_nodes]
    assert np.abs(changed - expected).max() < 1e-9
    assert np.abs(changed - start).max() > 0.05  # the effect does something


def test_conductivity_factor_equals_scaling_the_materials(testcell_data, real_case):
    # the floor alone uses concrete, polystyrene and heavy concrete
    scaled = copy.deepcopy(testcell_data)
    for name in ("concrete", "polystyrene", "heavy_concrete"):
        scaled["materials"][name]["conductivity"] *= 2.5
    by_factor = EFFECTS["conductivity"].apply(parse_building(testcell_data), "floor", {"factor": 2.5})
    assert np.abs(direct(by_factor, real_case) - direct(parse_building(scaled), real_case)).max() < 1e-9


def test_convection_factor_equals_scaling_every_inside_coefficient(testcell_data, real_case):
    scaled = copy.deepcopy(testcell_data)
    for c in scaled["components"]:
        c["inside"]["h_conv"] *= 0.02
    by_factor = EFFECTS["inside_convection"].apply(parse_building(testcell_data), "cell", {"factor": 0.02})
    assert np.abs(direct(by_factor, real_case) - direct(parse_building(scaled), real_case)).max() < 1e-9


def test_ground_coupling_is_a_boundary_face(testcell_data, testcell):
    after = EFFECTS["ground_coupling"].apply(testcell, "floor", {"U": 0.5, "T_ground": 24.0})
    assert after.component("floor").outside == Boundary(temperature=24.0, h=0.5)
    floor = next(c for c in after.to_json()["components"] if c["name"] == "floor")
    assert floor["outside"] == {"type": "boundary", "temperature": 24.0, "h": 0.5}
    # the building it came from is unchanged
    assert testcell.to_json() == testcell_data
    assert EFFECTS["ground_coupling"].read(after, "floor") == {"U": 0.5, "T_ground": 24.0}
    # once coupled, the floor is no longer adiabatic: the effect cannot be added twice
    assert not EFFECTS["ground_coupling"].applies(after, "floor")


@pytest.mark.parametrize("U, says", [(-1.0, r"-1\.0 is less than or equal to the minimum of 0"),
                                     (float("nan"), "nan is not of type 'number'")])
def test_a_ground_conductance_that_is_none_is_refused_not_dropped(testcell, U, says):
    """U = 0 is no coupling; a negative or NaN U is not a conductance, and was once taken as 0."""
    assert EFFECTS["ground_coupling"].apply(testcell, "floor", {"U": 0.0}).to_json() == testcell.to_json()
    with pytest.raises(InputError, match=r"outside\.h: " + says):
        EFFECTS["ground_coupling"].apply(testcell, "floor", {"U": U, "T_ground": 15.0})


def test_every_effect_reads_back_what_it_writes(testcell):
    for effect, target, values in CASES:
        after = EFFECTS[effect].apply(testcell, target, values)
        assert EFFECTS[effect].read(after, target) == pytest.approx(values), effect


def evidence(*components):
    """ga.locate's `components`, most evident first, with made-up shares."""
    return [{"component": c, "node": 0, "J": float(i), "share": 0.2 - 0.01 * i} for i, c in enumerate(components)]


def test_every_round_calibrates_every_zone_effect_and_the_evident_and_unmeasured_components(testcell):
    """The physics a round calibrates, whatever the residual says: every zone effect of the
    objective zone, the component effects of the three most evident components and of those no
    sensor sits in (the paper's sensors: nodes 1, 7, 9, 16, 17 and the air)."""
    zone = [("infiltration", "cell"), ("internal_gain", "cell"), ("inside_convection", "cell"),
            ("internal_mass", "cell"), ("envelope_conductance", "cell")]  # the registry's order
    sensors = [1, 7, 9, 16, 17, 23]
    pairs = physical(testcell, evidence("floor", "roof", "door", "east_wall"), ["cell"], sensors, Policy())
    assert pairs[:len(zone)] == zone
    # the floor: adiabatic below, and it receives the window's sun
    for pair in [("ground_coupling", "floor"), ("conductivity", "floor"), ("solar_transmittance", "window"),
                 ("solar_absorptance", "roof"), ("conductivity", "door"),
                 # no sensor: the walls but the east one, the window
                 ("conductivity", "west_wall"), ("solar_absorptance", "north_wall"), ("conductivity", "window")]:
        assert pair in pairs, pair
    # the fourth most evident component, measured, removing less than a quarter: not calibrated
    assert ("conductivity", "east_wall") not in pairs
    evident = [*evidence("floor", "roof", "door"), {"component": "east_wall", "node": 1, "J": 3.0, "share": 0.3}]
    assert ("conductivity", "east_wall") in physical(testcell, evident, ["cell"], sensors, Policy())
    # no shape in the physics; a zone without a heat input has no heater lag or split
    assert not {"daily_gain", "proportional_gain", "heat_input_lag", "heat_input_split"} & {e for e, _ in pairs}
    # the air alone measured: every component is calibrated
    alone = physical(testcell, [], ["cell"], [23], Policy())
    assert {t for e, t in alone if e == "conductivity"} == {c.name for c in testcell.components}


def test_a_zone_with_supply_air_gets_a_thermal_bridge_not_an_infiltration():
    from .test_zones import multizone_with_everything
    b = multizone_with_everything()
    # zone A has supply air (flow known): its air-to-outside term is a bridge; zone B has none
    pairs = physical(b, [], ["A", "B"], [], Policy())
    assert ("thermal_bridge", "A") in pairs and ("infiltration", "A") not in pairs
    assert ("infiltration", "B") in pairs
    # bridges to the boundary columns the zone's surfaces see (A's floor sees T_cellar)
    assert ("thermal_bridge", "A->T_cellar") in pairs
    # a zone with a heat input: the heater's lag and the input's split; with shaded glazing: their leak
    assert {("heat_input_lag", "B"), ("heat_input_split", "B"), ("shading_transmittance", "A")} <= set(pairs)
    # a partition is a component of the zones on both its sides: unmeasured, B's calibrates it too
    assert ("conductivity", "partition") in physical(b, [], ["B"], [], Policy())
    assert ("conductivity", "partition") not in physical(b, [], ["B"], b.component("partition").node_ids[:1], Policy())
    after = EFFECTS["heat_input_split"].apply(b, "B", {"f_r": 0.8})
    assert after.zone("B").heat_input_radiative_fraction == 0.8
    after = EFFECTS["thermal_bridge"].apply(b, "A->T_cellar", {"UA": 2.5})
    assert dict(after.zone("A").thermal_bridges) == {"T_cellar": 2.5}


def test_an_effect_that_moves_an_input_column_keeps_the_fmu_inputs(tmp_path, real_case):
    # a bridge from the air to the floor's boundary column: the zone's bridge names the column
    # before the component does, so the building's own input order changes with the effect
    from .test_zones import multizone_with_everything
    from nodeforce.model.case import Case
    b = multizone_with_everything()
    target = "A->T_cellar"
    assert EFFECTS["thermal_bridge"].applies(b, target)
    with_bridge = EFFECTS["thermal_bridge"].apply(b, target, {"UA": 6.0})
    assert assemble(with_bridge).input_names != assemble(b).input_names
    net = assemble(b)
    n_rows = 2 * 96 + 1
    rng = np.random.default_rng(2)
    U = rng.uniform(0, 30, (n_rows, len(net.input_names)))
    U[:, net.input_names.index("blind")] = 1.0
    times = real_case.times[:n_rows]
    case = Case(times, 900.0, net.input_names, U, np.full((n_rows, net.n_nodes), np.nan), building=b)
    fmu = build_fmu(b, tmp_path / "m.fmu", effect=("thermal_bridge", target))
    with FmuInstance(fmu) as instance:
        changed = simulate_fmu(instance, case, parameters={"thermal_bridge.UA": 6.0})
    expected = simulate(with_bridge, assemble(with_bridge, net.input_names), U, 900.0, case.measured)
    assert np.abs(changed - expected).max() < 1e-9


def test_a_gain_in_a_zone_declared_unoccupied_is_implausible(testcell):
    from nodeforce.diagnosis.policy import implausible
    assert implausible(testcell, "internal_gain", "cell") is None  # occupancy not declared
    empty = testcell.edited(lambda d: d["zones"][0].update(occupied=False))
    assert "unoccupied" in implausible(empty, "internal_gain", "cell")
    assert "unoccupied" in implausible(empty, "daily_gain", "cell")
    assert implausible(empty, "infiltration", "cell") is None


def test_the_residual_left_chooses_the_shapes():
    """Shapes are the residual's to choose: a gain following each input it follows, a daily gain
    where it follows the clock, a workday gain where it tells working from rest days, every input and the clock where it is structured but follows none
    (inputs of one kind are nearly collinear), nothing where it is white."""
    from nodeforce.diagnosis.candidates import shapes
    from .test_zones import multizone_with_everything
    b = multizone_with_everything()
    left = {"white": False, "time_of_day": {"significant": False},
            "follows": [{"input": "heater", "lag_hours": 0.0, "correlation": -0.7}]}
    assert shapes(b, left, ["B"]) == [("proportional_gain", "B->heater")]
    clock = {**left, "follows": []}
    structured = shapes(b, clock, ["A"])
    assert structured[0] == ("daily_gain", "A") and ("proportional_gain", "A->I_south") in structured
    assert shapes(b, {**left, "white": True}, ["B"]) == []
    # a gain on working days only where the residual tells them from the rest days, and wherever
    # every shape is tried if the window holds both kinds of day
    weekly = {"significant": True, "p_value": 1e-4}
    assert ("workday_gain", "B") in shapes(b, {**left, "working_days": weekly}, ["B"])
    assert ("workday_gain", "B") not in shapes(b, {**left, "working_days": {**weekly, "significant": False}}, ["B"])
    assert ("workday_gain", "A") in shapes(b, {**clock, "working_days": {**weekly, "significant": False}}, ["A"])
    assert ("workday_gain", "A") not in structured  # the window held one kind of day


def test_every_effect_parameter_has_a_unit_the_fmus_declare():
    """The FMU takes an effect's parameters from the registry: each unit must be one FMI is told
    (a unit missing from fmu_build.description.UNITS would stop every export of the effect)."""
    from nodeforce.fmu_build.description import EFFECT_UNITS, UNITS
    for effect in EFFECTS.values():
        for p in effect.parameters:
            unit = EFFECT_UNITS.get(p.unit, p.unit)
            assert unit is None or unit in UNITS, (effect.id, p.name, p.unit)
