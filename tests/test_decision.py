"""The decision's rules, on candidates built by hand (no simulation): physics refuses what the
data cannot pin down or the building's description rules out, and prefers a physical effect
with few parameters to a shape unless the data show it worse, pair by pair."""
import numpy as np
import pytest

from nodeforce.diagnose.candidates import objection, preference
from nodeforce.diagnose.loop import decide
from nodeforce.model.significance import change_of_J
from nodeforce.model.building import parse_building

STEPS = 4 * 96  # four days of selection window at 15 min


def parameter(value, std, identifiable=True, on_bound=False):
    return {"value": value, "std": std, "identifiable": identifiable, "on_bound": on_bound}


@pytest.fixture
def unoccupied(testcell_data):
    data = {**testcell_data, "zones": [{**testcell_data["zones"][0], "occupied": False}]}
    return parse_building(data)


def test_a_parameter_the_data_do_not_determine_is_refused(testcell):
    assert "not identifiable" in objection(testcell, "internal_gain", "cell",
                                           {"Q": parameter(50.0, 40.0, identifiable=False)})
    assert objection(testcell, "internal_gain", "cell", {"Q": parameter(50.0, 4.0)}) is None


def test_a_parameter_on_a_bound_of_its_range_is_refused(testcell):
    assert "bound" in objection(testcell, "solar_absorptance", "roof",
                                {"alpha": parameter(1.0, 0.01, identifiable=False, on_bound=True)})


def test_a_negative_gain_is_refused_where_physics_forbids_it(testcell):
    # the real air-only record's -545 +- 16 W: well determined, and a heat sink
    assert "negative gain" in objection(testcell, "internal_gain", "cell", {"Q": parameter(-545.0, 16.0)})
    # sun through an opening cannot take heat away; a heat input may be overstated, but not by more than itself
    assert "negative gain" in objection(testcell, "proportional_gain", "cell->I_window", {"k": parameter(-0.3, 0.01)})


def test_a_factor_outside_physical_limits_is_refused(testcell):
    assert "physical limits" in objection(testcell, "conductivity", "door", {"factor": parameter(15.0, 0.5)})
    assert objection(testcell, "conductivity", "door", {"factor": parameter(3.4, 0.2)}) is None


def test_a_gain_in_a_zone_declared_unoccupied_is_refused(unoccupied):
    values = {"mean": parameter(46.0, 3.0), **{t: parameter(1.0, 5.0, identifiable=False)
                                                for t in ("cos1", "sin1", "cos2", "sin2", "cos3", "sin3", "cos4", "sin4")}}
    assert "unoccupied" in objection(unoccupied, "daily_gain", "cell", values)


def test_a_ground_coupling_is_judged_by_the_flux_the_data_fix(testcell):
    # U and T_ground trade off: neither is determined, the heat flux they give is
    traded = {"U": parameter(0.8, 0.5, identifiable=False), "T_ground": parameter(24.0, 3.0, identifiable=False)}
    flux = {"ground_heat_flux": {"value": 4.0, "std": 0.3, "unit": "W/m2"}}
    assert objection(testcell, "ground_coupling", "floor", traded, flux) is None
    on_bound = {**traded, "T_ground": parameter(-10.0, 3000.0, identifiable=False, on_bound=True)}
    assert objection(testcell, "ground_coupling", "floor", on_bound, flux) is None
    assert "not identifiable" in objection(testcell, "ground_coupling", "floor", traded,
                                           {"ground_heat_flux": {"value": 4.0, "std": 3.0, "unit": "W/m2"}})


def test_a_heater_node_is_judged_by_the_time_constant_the_data_fix_but_must_stay_inside_its_range(testcell):
    # C_h and H_h trade off along tau = C_h / H_h: neither is determined, tau is
    traded = {"C_h": parameter(9.4e4, 4.8e4, identifiable=False), "H_h": parameter(59.0, 39.0, identifiable=False)}
    tau = {"heater_time_constant": {"value": 1590.0, "std": 120.0, "unit": "s"}}
    assert objection(testcell, "heat_input_lag", "cell", traded, tau) is None
    assert "not identifiable" in objection(testcell, "heat_input_lag", "cell", traded,
                                           {"heater_time_constant": {"value": 1590.0, "std": 900.0, "unit": "s"}})
    # a conductance on its bound is a node that is not there, whatever tau says
    on_bound = {**traded, "H_h": parameter(0.01, 0.0002, on_bound=True)}
    assert "bound" in objection(testcell, "heat_input_lag", "cell", on_bound, tau)


def test_physics_comes_before_shapes_and_fewer_parameters_before_more():
    assert preference("conductivity") < preference("proportional_gain") < preference("daily_gain")
    assert preference("infiltration") < preference("ground_coupling")


# --- decide() on hand-made candidates: the model without them leaves a daily wave of 0.5 C plus
# white noise of 0.1 C on the selection window; each candidate leaves part of it

def _window(rng):
    t = np.arange(STEPS)
    wave = 0.5 * np.sin(2 * np.pi * t / 96)
    return wave, rng.normal(0.0, 0.1, STEPS)


def candidate(effect, target, parameters, left, n_fit=1000, J_fit=10.0):
    """A calibrated candidate's record as diagnose.loop.assess_all makes it, leaving residual
    `left` (C) on the selection window of the model without it `before` (module docstring)."""
    residual = left[:, None]
    return {"effect": effect, "target": target, "parameters": parameters, "derived": {},
            "selection": {"J": float(left @ left), "rmse": float(np.sqrt(np.mean(left ** 2))), "n": STEPS},
            "bic": n_fit * np.log(J_fit / n_fit) + len(parameters) * np.log(n_fit)}, residual


def judge(building, made, before_left):
    results, residuals = [], {}
    for record, residual in made:
        results.append(record)
        before = before_left[:, None]
        record["selection_fall"] = dict(zip(("J", "sd"), change_of_J(before, residual, 96)))
        residuals[f"{record['effect']}@{record['target']}"] = residual
    before = {"calibration": {"J": 100.0, "n": 1000},
              "selection": {"J": float(before_left @ before_left), "n": STEPS,
                            "rmse": float(np.sqrt(np.mean(before_left ** 2)))}}
    return decide(building, results, before, 0.1, residuals)


def test_a_physical_effect_wins_over_a_shape_the_data_cannot_tell_from_it(testcell):
    rng = np.random.default_rng(1)
    wave, noise = _window(rng)
    physical = candidate("conductivity", "door", {"factor": parameter(3.0, 0.2)}, noise + 0.02 * wave)
    shape = candidate("daily_gain", "cell", {"mean": parameter(40.0, 3.0), **{
        t: parameter(1.0, 5.0, identifiable=False) for t in ("cos1", "sin1", "cos2", "sin2", "cos3", "sin3",
                                                             "cos4", "sin4")}}, noise + 0.01 * wave)
    chosen, decision = judge(testcell, [shape, physical], noise + wave)
    assert chosen["effect"] == "conductivity", decision["reason"]
    # where the shape fits measurably better, it is chosen, and told as a heat source the model lacks
    far = candidate("conductivity", "door", {"factor": parameter(3.0, 0.2)}, noise + 0.4 * wave)
    chosen, decision = judge(testcell, [shape, far], noise + wave)
    assert chosen["effect"] == "daily_gain"
    assert "an unexplained heat source, acting with a daily profile" in decision["reason"].lower()


def test_a_candidate_physics_refuses_is_never_added_but_suggested(testcell):
    rng = np.random.default_rng(2)
    wave, noise = _window(rng)
    sink = candidate("internal_gain", "cell", {"Q": parameter(-545.0, 16.0)}, noise)
    weaker = candidate("conductivity", "door", {"factor": parameter(3.0, 0.2)}, noise + 0.3 * wave)
    chosen, decision = judge(testcell, [sink, weaker], noise + wave)
    assert chosen["effect"] == "conductivity"
    assert [s["candidate"] for s in decision["suggestions"]] == ["internal_gain@cell"]
    assert "negative gain" in decision["suggestions"][0]["reason"] and "Not added" in decision["reason"]
    # alone, it leaves the model as it is
    chosen, decision = judge(testcell, [sink], noise + wave)
    assert chosen is None and decision["chosen"] is None
