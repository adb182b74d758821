"""Sensors on a component's face: a surface temperature (the face's node, a forcing candidate) and
a heat flux density through the face, which the model computes and `nodeforce compare` reports
beside the reading."""
import copy
import json

import numpy as np
import pandas as pd
import pytest

from nodeforce.cli import main
from nodeforce.model.building_file import parse_building
from nodeforce.model.case import measured_case, prepare_case
from nodeforce.model.effects import EFFECTS
from nodeforce.model.errors import InputError
from nodeforce.model.integrate import simulate
from nodeforce.model.network import assemble, face_heat_flux
from nodeforce.model.synth import pseudo_measurements
from tests.conftest import DATA, SENSORS, record_times

from .test_house_effects import H_O, OUTDOOR, light_house, light_wall
from .test_zones import steady

FLUX = {"roof_flux": {"component": "roof", "face": "inside", "quantity": "heat_flux"},
        "roof_out_flux": {"component": "roof", "face": "outside", "quantity": "heat_flux"},
        "roof_inside": {"component": "roof", "face": "inside"}}


def with_sensors(data, sensors=FLUX):
    data = copy.deepcopy(data)
    data.setdefault("sensors", {}).update(sensors)
    return data


def test_a_light_wall_in_steady_state_passes_the_heater_s_power_through_both_faces():
    """One room, one wall of no capacity: in steady state all of Q crosses the wall, Q / A in
    through the inside face and Q / A out through the outside face."""
    data = light_house([{"name": "room", "volume": 40.0, "heat_input": "heater"}], [light_wall("wall", "room", OUTDOOR)])
    b = parse_building(data)
    inputs = {"T_out": 3.0, "T_sky": 3.0, "I_wall": 0.0, "heater": 600.0}
    T = steady(b, inputs)
    net = assemble(b)
    u = np.array([[inputs[n] for n in net.input_names]])
    assert face_heat_flux(b, net, T[None], u, "wall", "inside")[0] == pytest.approx(600.0 / 20.0, rel=1e-9)
    assert face_heat_flux(b, net, T[None], u, "wall", "outside")[0] == pytest.approx(-600.0 / 20.0, rel=1e-9)
    # the air is as far above the outdoors as the wall's conductance says
    assert T[b.zone("room").air_node - 1] - 3.0 == pytest.approx(600.0 / H_O, rel=1e-9)


def test_what_crosses_both_faces_is_what_the_component_stores(testcell, real_case):
    """Backward Euler's balance of the roof's nodes: A (q_inside + q_outside) = sum C_k dT_k/dt at
    every step, the sun its outside face absorbs included."""
    net = assemble(testcell)
    T = simulate(testcell, net, real_case.U, real_case.dt, real_case.measured, include_start=True)
    roof = testcell.component("roof")
    q = sum(face_heat_flux(testcell, net, T[1:], real_case.U[1:], "roof", face) for face in ("inside", "outside"))
    own = [i - 1 for i in roof.node_ids]
    stored = (np.diff(T[:, own], axis=0) * net.C[own]).sum(axis=1) / real_case.dt
    assert np.abs(roof.area * q - stored).max() < 1e-7 * np.abs(stored).max()
    assert np.abs(stored).max() > 50.0  # W: the roof does store and give back heat


def test_face_sensors_name_nodes_and_flux_sensors_name_none(testcell_data, testcell):
    b = parse_building(with_sensors(testcell_data))
    assert b.sensors["roof_inside"] == testcell.component("roof").node_ids[0]
    assert "roof_flux" not in b.sensors and b.flux_sensors == {"roof_flux": ("roof", "inside"),
                                                               "roof_out_flux": ("roof", "outside")}
    for sensor, says in (({"component": "roof", "depth": 0.0, "quantity": "heat_flux"}, "at a face"),
                         ({"component": "roof", "face": "top"}, r"face: 'top' is not one of \['inside', 'outside'\]"),
                         ({"component": "roof", "face": "inside", "depth": 0.0}, "one of them"),
                         ({"component": "roof", "face": "inside", "quantity": "power"},
                          r"quantity: 'power' is not one of \['temperature', 'heat_flux'\]")):
        with pytest.raises(InputError, match=r"sensors\.s.*" + says):
            parse_building(with_sensors(testcell_data, {"s": sensor}))


def test_a_flux_column_is_kept_as_a_flux_not_a_temperature(testcell_data, weather):
    b = parse_building(with_sensors(testcell_data))
    times = record_times(2)
    frame = pd.DataFrame({"T23": np.full(len(times), 25.0), "roof_flux": np.linspace(-400.0, 400.0, len(times))},
                         index=times)
    frame.iloc[5, 1] = np.nan
    case = prepare_case(b, weather, frame)
    assert list(case.fluxes) == ["roof_flux"] and case.measured_ids == [23]
    assert np.array_equal(case.fluxes["roof_flux"], frame["roof_flux"].to_numpy(), equal_nan=True)  # no gap filled
    assert len(case.window(10, 20).fluxes["roof_flux"]) == 11


@pytest.mark.slow  # two FMUs built and run
def test_compare_reports_the_model_s_flux_beside_the_reading(tmp_path, testcell_data, weather):
    """The reading is the true building's flux through the roof's faces: compare gives it back for
    that building's file, and not for one that lacks its air change."""
    data = with_sensors(testcell_data)
    written = parse_building(data)
    truth = EFFECTS["infiltration"].apply(written, "cell", {"n": 2.0})
    measurements = pseudo_measurements(truth, weather, record_times(3), SENSORS, noise_sd=0.0, history_days=3)
    case = measured_case(truth, weather, measurements, burn_in_days=1)  # from the weather's history, as compare runs it
    net, h = assemble(truth), case.history_steps
    T = simulate(truth, net, case.U, case.dt, case.measured, burn_in_steps=case.burn_in_steps, include_start=True,
                 steady_start=True, substeps=case.substeps, history_steps=h)[h:]
    for sensor in ("roof_flux", "roof_out_flux"):
        measurements[sensor] = face_heat_flux(truth, net, T, case.U[h:], "roof", truth.flux_sensors[sensor][1])
    measurements.to_csv(tmp_path / "m.csv", date_format="%Y-%m-%dT%H:%M:%S%z")
    (tmp_path / "written.json").write_text(json.dumps(data))
    (tmp_path / "truth.json").write_text(json.dumps(truth.to_json()))
    assert main(["compare", str(tmp_path / "truth.json"), str(tmp_path / "written.json"), "--weather",
                 str(DATA / "miami_tmy2.csv"), "--measurements", str(tmp_path / "m.csv"), "--burn-in-days", "1",
                 "-o", str(tmp_path / "out")]) == 0
    result = json.loads((tmp_path / "out" / "compare.json").read_text())
    right, wrong = (m["surface_heat_flux"] for m in result["models"])
    for sensor in ("roof_flux", "roof_out_flux"):
        assert right[sensor]["n"] == 2 * 96 and right[sensor]["component"] == "roof"
        assert right[sensor]["rmse"] < 1e-6
        assert right[sensor]["model_mean"] == pytest.approx(right[sensor]["measured_mean"], abs=1e-6)
    # the file without the air change keeps the room warmer: more heat into the roof from inside
    assert wrong["roof_flux"]["rmse"] > 0.1 and wrong["roof_flux"]["mean"] < 0
    md = (tmp_path / "out" / "compare.md").read_text()
    assert "Surface heat flux" in md and "roof_out_flux" in md
