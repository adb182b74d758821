"""The house-level effects (a boundary column's conductances, a zone's supply flow, the air two
zones exchange through an open door, a zone's measured heat input) against hand calculations,
the energy balance, the four FMUs, and a recovery through the diagnosis' calibration."""
import copy
import json
from dataclasses import replace

import numpy as np
import pandas as pd
import pytest

from nodeforce.cosim.fmi import FmuInstance
from nodeforce.cosim.run import simulate_fmu
from nodeforce.diagnosis.calibrate import Candidate, calibrate
from nodeforce.diagnosis.candidates import calibration_start, physical
from nodeforce.diagnosis.policy import Policy
from nodeforce.fmu_build.build import build_fmu
from nodeforce.model.building_file import load_building, parse_building
from nodeforce.model.case import Case
from nodeforce.model.effects import EFFECTS
from nodeforce.model.errors import InputError
from nodeforce.model.hlc import heat_loss_coefficient
from nodeforce.model.integrate import simulate
from nodeforce.model.network import assemble
from nodeforce.model.score import Objective

from .test_hlc import series
from .test_physics import boundary_heat_in
from .test_zones import multizone_with_everything, steady

RHO_C = 1.2 * 1005
HOUSE_EFFECTS = ("boundary_conductance", "supply_flow", "interzone_air_exchange", "heat_input_factor")
# a value of each on the multizone building's target, away from its neutral value
VALUES = {"boundary_conductance": ("T_cellar", {"factor": 0.55}), "supply_flow": ("A", {"factor": 0.6}),
          "interzone_air_exchange": ("A|B", {"V": 150.0}), "heat_input_factor": ("B", {"factor": 0.8})}
FOAM = {"conductivity": 0.04, "density": 0.0, "specific_heat": 1000.0}  # no capacity: a pure conductance


def light_wall(name, zone, outside, area=20.0, h_rad=5.0):
    return {"name": name, "area": area, "tilt": 90.0, "azimuth": 180.0, "layers": [["foam", 0.1]],
            "nodes": {"max_spacing": 1.0}, "inside": {"zone": zone, "h_conv": 3.0, "h_rad": h_rad}, "outside": outside}


OUTDOOR = {"type": "exterior", "h_conv": 20.0, "h_rad": 0.0, "solar_absorptance": 0.0}
H_O = series(20.0 * 3.0, 20.0 * 0.04 / 0.1, 20.0 * 20.0)  # W/K of a light wall to the outdoor air


def light_house(zones, components, **top):
    return {"format": "nodal-building/1", "name": "light house", "site": {"latitude": 45.0, "longitude": 5.0},
            "materials": {"foam": FOAM}, "zones": zones, "components": components, **top}


def test_a_boundary_factor_scales_the_walls_path_and_the_bridges_to_that_column():
    """A room whose one wall sees the column T_b through h = 8, and a bridge of 4 W/K to it:
    Q = H (T_air - T_b) with H = series(A h_c, f A k / d, f A h) + f UA."""
    data = light_house([{"name": "room", "volume": 40.0, "heat_input": "heater", "thermal_bridges": {"T_b": 4.0}}],
                       [light_wall("wall", "room", {"type": "boundary", "temperature": "T_b", "h": 8.0})])
    b = parse_building(data)
    assert EFFECTS["boundary_conductance"].targets(b) == ["T_b"]
    Q, T_b = 600.0, 12.0
    for f in (1.0, 0.4, 2.5):
        after = EFFECTS["boundary_conductance"].apply(b, "T_b", {"factor": f})
        H = series(20.0 * 3.0, f * 20.0 * 0.04 / 0.1, f * 20.0 * 8.0) + f * 4.0
        T = steady(after, {"T_out": 0.0, "T_sky": 0.0, "heater": Q, "T_b": T_b})
        assert T[after.zone("room").air_node - 1] == pytest.approx(T_b + Q / H, abs=1e-6)
        assert heat_loss_coefficient(after) == pytest.approx(H, rel=1e-9)


def test_a_supply_factor_scales_the_air_the_zone_gets():
    """T_air = (H_o T_out + f g T_sup + Q) / (H_o + f g), g = rho c V / 3600."""
    data = light_house([{"name": "room", "volume": 40.0, "heat_input": "heater",
                         "supply": {"flow": 100.0, "temperature": 16.0}}], [light_wall("wall", "room", OUTDOOR)])
    b = parse_building(data)
    Q, T_out, g = 500.0, -3.0, RHO_C * 100.0 / 3600
    for f in (1.0, 0.3, 0.0):
        after = EFFECTS["supply_flow"].apply(b, "room", {"factor": f})
        T = steady(after, {"T_out": T_out, "T_sky": T_out, "I_wall": 0.0, "heater": Q})
        expected = (H_O * T_out + f * g * 16.0 + Q) / (H_O + f * g)
        assert T[after.zone("room").air_node - 1] == pytest.approx(expected, abs=1e-6)
    # a zone with no supply, or none flowing, has nothing to scale
    assert EFFECTS["supply_flow"].targets(b) == ["room"]
    assert EFFECTS["supply_flow"].targets(b.edited(lambda d: d["zones"][0]["supply"].update(flow=0.0))) == []


NO_RAD = 1e-9  # W/m2/K: a radiant node with no coupling would be a singular row


def test_an_open_door_couples_two_airs_by_rho_c_v():
    """Rooms a (heated) and b, each with a wall to the outdoors, share a partition (conductance
    K_p from air to air, no radiation: h_rad 1e-9 W/m2/K, which moves nothing by 1e-6 K): with
    G = K_p + rho c V / 3600 and x = T_a - T_out, Q = (H_a + G H_b / (H_b + G)) x and
    T_b - T_out = G x / (H_b + G)."""
    data = light_house([{"name": "a", "volume": 40.0, "heat_input": "heater"}, {"name": "b", "volume": 30.0}],
                       [light_wall("wa", "a", OUTDOOR, h_rad=NO_RAD),
                        light_wall("wb", "b", OUTDOOR, area=10.0, h_rad=NO_RAD),
                        light_wall("door", "a", {"type": "zone", "zone": "b", "h_conv": 3.0, "h_rad": NO_RAD},
                                   area=2.0, h_rad=NO_RAD)])
    b = parse_building(data)
    assert EFFECTS["interzone_air_exchange"].targets(b) == ["a|b"]
    H_a, H_b = H_O, series(10.0 * 3.0, 10.0 * 0.04 / 0.1, 10.0 * 20.0)
    K_p = series(2.0 * 3.0, 2.0 * 0.04 / 0.1, 2.0 * 3.0)
    Q, T_out = 800.0, 5.0
    for V in (0.0, 60.0, 400.0):
        after = EFFECTS["interzone_air_exchange"].apply(b, "a|b", {"V": V})
        G = K_p + RHO_C * V / 3600
        x = Q / (H_a + G * H_b / (H_b + G))
        T = steady(after, {"T_out": T_out, "T_sky": T_out, "I_wa": 0.0, "I_wb": 0.0, "I_door": 0.0, "heater": Q})
        assert T[after.zone("a").air_node - 1] == pytest.approx(T_out + x, abs=1e-6)
        assert T[after.zone("b").air_node - 1] == pytest.approx(T_out + G * x / (H_b + G), abs=1e-6)
        # air at one temperature everywhere carries nothing between the zones: the HLC is the walls'
        assert heat_loss_coefficient(after) == pytest.approx(H_a + H_b, rel=1e-9)
    # zones that share no component are not offered an exchange; one declared is
    apart = copy.deepcopy(data)
    apart["components"].pop()
    assert EFFECTS["interzone_air_exchange"].targets(parse_building(apart)) == []
    apart["zones"][1]["air_exchange"] = {"a": 20.0}
    declared = parse_building(apart)
    assert EFFECTS["interzone_air_exchange"].targets(declared) == ["a|b"]
    assert EFFECTS["interzone_air_exchange"].read(declared, "a|b") == {"V": 20.0}
    # written where the file declares it, not a second time on the other zone
    moved = EFFECTS["interzone_air_exchange"].apply(declared, "a|b", {"V": 70.0})
    assert dict(moved.zone("b").air_exchange) == {"a": 70.0} and moved.zone("a").air_exchange == ()


def test_a_heat_input_factor_scales_what_the_heater_delivers():
    """T_air = T_out + f Q / H_o; with a radiative part and a heater's own node, the steady heat
    that leaves through the wall's outside face is f Q."""
    data = light_house([{"name": "room", "volume": 40.0, "heat_input": ["heater", "meter2"]}],
                       [light_wall("wall", "room", OUTDOOR)])
    b = parse_building(data)
    inputs = {"T_out": 2.0, "T_sky": 2.0, "I_wall": 0.0, "heater": 400.0, "meter2": 200.0}
    for f in (1.0, 0.7, 1.6):
        after = EFFECTS["heat_input_factor"].apply(b, "room", {"factor": f})
        T = steady(after, inputs)
        assert T[after.zone("room").air_node - 1] == pytest.approx(2.0 + f * 600.0 / H_O, abs=1e-6)
        lagged = after.edited(lambda d: d["zones"][0].update(heat_input_radiative_fraction=0.3,
                                                             heat_input_lag={"capacity": 1e4, "conductance": 20.0}))
        T = steady(lagged, inputs)
        outer = lagged.component("wall").node_ids[-1] - 1
        assert 20.0 * 20.0 * (T[outer] - 2.0) == pytest.approx(f * 600.0, rel=1e-9)


def test_the_neutral_values_are_the_building_as_declared():
    b = multizone_with_everything()
    declared = assemble(b)
    for effect in HOUSE_EFFECTS:
        target, _ = VALUES[effect]
        assert EFFECTS[effect].applies(b, target)
        neutral = assemble(EFFECTS[effect].apply(b, target, {}), declared.input_names)
        for name in ("C", "A", "B", "q"):
            assert np.array_equal(getattr(neutral, name), getattr(declared, name)), (effect, name)


def with_all(building):
    for effect in HOUSE_EFFECTS:
        target, values = VALUES[effect]
        building = EFFECTS[effect].apply(building, target, values)
    return building


def test_the_energy_balance_closes_every_step_with_every_house_effect():
    """Stored heat = heat in through the outside faces, the air and the heat inputs, written term
    by term (tests/test_physics.boundary_heat_in); the exchange between zones moves heat inside
    only."""
    b = with_all(multizone_with_everything())
    net = assemble(b)
    dt, n_rows = 600.0, 2 * 144 + 1
    rng = np.random.default_rng(4)
    scale = {"T_out": 30, "T_sky": 30, "I_south": 800, "I_wB": 500, "heater": 1500, "duct": -200,
             "T_supply": 25, "T_cellar": 20, "blind": 1}
    U = rng.uniform(0, 1, (n_rows, len(net.input_names))) * np.array([scale[n] for n in net.input_names])
    measured = np.full((n_rows, net.n_nodes), np.nan)
    measured[0, :] = 20.0
    T = simulate(b, net, U, dt, measured, warmup_days=0, include_start=True)
    assert np.ptp(T[:, b.zone("A").air_node - 1] - T[:, b.zone("B").air_node - 1]) > 1.0  # the door carries heat
    for n in range(1, n_rows):
        stored = np.sum(net.C * (T[n] - T[n - 1])) / dt
        heat_in = boundary_heat_in(b, T[n], dict(zip(net.input_names, U[n])))
        assert abs(stored - heat_in) <= 1e-7 * max(abs(stored), abs(heat_in), 1.0), n


def test_a_building_file_that_declares_them_round_trips_and_bad_ones_are_refused(tmp_path):
    data = with_all(multizone_with_everything()).to_json()
    assert data["boundary_conductance_factors"] == {"T_cellar": 0.55}
    assert data["zones"][0]["supply"]["flow_factor"] == 0.6 and data["zones"][0]["air_exchange"] == {"B": 150.0}
    assert data["zones"][1]["heat_input_factor"] == 0.8
    path = tmp_path / "house.json"
    path.write_text(json.dumps(data))
    loaded = load_building(path)  # the JSON Schema too
    assert loaded.to_json() == data
    for effect in HOUSE_EFFECTS:
        target, values = VALUES[effect]
        assert EFFECTS[effect].read(loaded, target) == pytest.approx(values)

    def refused(change, match):
        bad = copy.deepcopy(data)
        change(bad)
        with pytest.raises(InputError, match=match):
            parse_building(bad)

    refused(lambda d: d.update(boundary_conductance_factors={"T_attic": 0.5}),
            r"boundary_conductance_factors\.T_attic: names no boundary temperature column .*T_cellar")
    refused(lambda d: d["zones"][0]["air_exchange"].update(C=1.0), r"air_exchange\.C: names no zone")
    refused(lambda d: d["zones"][0]["air_exchange"].update(A=1.0), "a zone exchanges no air with itself")
    refused(lambda d: d["zones"][1].update(air_exchange={"A": 5.0}), "declared on both zones")
    refused(lambda d: d["zones"][0].update(heat_input_factor=0.9),
            r"zones\[0\]: 'heat_input' is a required property \(with heat_input_factor\)")
    refused(lambda d: d["zones"][0]["supply"].update(flow_factor=-1.0),
            r"supply\.flow_factor: -1\.0 is less than the minimum of 0")


def test_each_is_offered_where_the_building_has_what_it_acts_on(testcell):
    b = multizone_with_everything()
    pairs = physical(b, [], ["A", "B"], [], Policy())
    for effect in HOUSE_EFFECTS:
        assert (effect, VALUES[effect][0]) in pairs, effect
    # a zone whose floor's outside is the cellar column is offered the cellar's conductances
    assert ("boundary_conductance", "T_cellar") in physical(b, [], [b.component("floor").inside.zone], [], Policy())
    # the test cell has one zone, no supply, no boundary column and no heat input
    assert not {e for e, _ in physical(testcell, [], ["cell"], [], Policy())} & set(HOUSE_EFFECTS)
    # an open door starts where it carries something; the physical limits of the factors
    assert calibration_start(b, "interzone_air_exchange", "A|B")["V"] > 0
    assert Policy().limits(b, "heat_input_factor", "B", "factor") == (0.5, 2.0)
    assert Policy().limits(b, "supply_flow", "A", "factor") == (0.1, 10.0)


def random_case(b, n_rows, seed):
    net = assemble(b)
    rng = np.random.default_rng(seed)
    times = pd.date_range("2014-04-09", periods=n_rows, freq="15min", tz="+01:00", name="time")
    hours = np.arange(n_rows) * 0.25
    day = np.sin(2 * np.pi * hours / 24)
    columns = {"T_out": 8 + 6 * day, "T_sky": -2 + 6 * day, "I_south": np.clip(600 * day, 0, None),
               "I_wB": np.clip(300 * day, 0, None), "heater": rng.choice([0.0, 900.0], n_rows),
               "duct": np.full(n_rows, -60.0), "T_supply": 17 + 3 * np.cos(2 * np.pi * hours / 24),
               "T_cellar": 13 + 0.5 * np.sin(2 * np.pi * hours / 72), "blind": (day > 0.5).astype(float)}
    U = np.column_stack([columns[n] for n in net.input_names])
    return Case(times, 900.0, net.input_names, U, np.full((n_rows, net.n_nodes), np.nan), building=b)


@pytest.mark.slow  # four effects, four FMU kinds
@pytest.mark.parametrize("kind", ["python", "standalone", "python-fmi3", "standalone-fmi3"])
def test_the_fmus_with_a_house_effect_equal_the_direct_model(tmp_path, kind):
    b = multizone_with_everything()
    n_rows = 2 * 96 + 1
    case = random_case(b, n_rows, seed=6)
    case.measured[0, b.zone("B").air_node - 1] = 18.0
    plain = simulate(b, assemble(b), case.U, 900.0, case.measured)
    for effect in HOUSE_EFFECTS:
        target, values = VALUES[effect]
        fmu = build_fmu(b, tmp_path / f"{effect}.fmu", effect=(effect, target), kind=kind)
        after = EFFECTS[effect].apply(b, target, values)
        expected = simulate(after, assemble(after, case.input_names), case.U, 900.0, case.measured)
        with FmuInstance(fmu) as instance:
            T = simulate_fmu(instance, replace(case, building=after), parameters={f"{effect}.{k}": v for k, v in values.items()})
        assert np.abs(T - expected).max() < 1e-9, effect
        assert np.abs(expected - plain).max() > 0.05, effect  # the effect does something


@pytest.mark.slow  # four calibrations on the direct model (equal to every FMU kind: test_the_fmus_with_a_house_effect_equal_the_direct_model)
@pytest.mark.parametrize("effect", HOUSE_EFFECTS)
def test_a_calibration_recovers_the_effect_from_a_record_of_both_airs(tmp_path, effect):
    """The record of a house whose file leaves the effect out (5 days, 0.05 C noise on both
    airs): the calibration on the direct model finds the value within its uncertainty."""
    b = multizone_with_everything()
    target, values = VALUES[effect]
    truth = EFFECTS[effect].apply(b, target, values)
    n_rows = 5 * 96 + 1
    case = random_case(b, n_rows, seed=7)
    T = simulate(truth, assemble(truth, case.input_names), case.U, 900.0, None, warmup_days=30, include_start=True)
    objective = Objective.of(b, ["A", "B"])
    air = [i - 1 for i in objective.air_nodes]
    measured = np.full_like(case.measured, np.nan)
    measured[:, air] = T[:, air] + np.random.default_rng(8).normal(0.0, 0.05, (n_rows, len(air)))
    record = Case(case.times, 900.0, case.input_names, case.U, measured, building=b).with_burn_in(1)
    found, _, _ = calibrate(Candidate(b, effect, target), record, objective)
    (name, true), = values.items()
    p = found[name]
    assert p["identifiable"], p
    assert abs(p["value"] - true) <= 3 * p["std"], p
    assert abs(p["value"] - true) <= 0.05 * true, p
