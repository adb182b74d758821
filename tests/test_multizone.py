"""A converted multi-zone EnergyPlus model end to end (issue 44, item 4): examples/multizone's
three zones, their interzone partitions, windows, scheduled gains and night ventilation,
through `nodeforce convert`; a record with an infiltration its file does not declare, in one
office only; the diagnosis finds it there."""
import json
from pathlib import Path

import pandas as pd
import pytest

from nodeforce.api import convert_idf
from nodeforce.diagnosis.loop import diagnose
from nodeforce.ga.locate import Execution, SearchSettings
from nodeforce.iotools.typical_year import convert_typical_year
from nodeforce.iotools.weather import read_weather
from nodeforce.model.case import prepare_case
from nodeforce.model.effects import EFFECTS
from nodeforce.model.score import Objective
from nodeforce.model.synth import pseudo_measurements

ROOT = Path(__file__).resolve().parents[1]

pytestmark = pytest.mark.slow


def typical_year(tmp_path):
    """The weather CSV of a typical year pvlib bundles (Greensboro's TMY3) put in 2017. The
    buildings keep their own site: the record and the diagnosis read the same weather, which is
    all these tests need."""
    import pvlib
    convert_typical_year(Path(pvlib.__file__).parent / "data" / "723170TYA.CSV", tmp_path / "w.csv", year=2017)
    return tmp_path / "w.csv"


def test_three_zones_diagnosed_end_to_end(tmp_path):
    building = convert_idf(ROOT / "examples" / "multizone" / "three_zones.idf")
    typical_year(tmp_path)
    weather = read_weather(tmp_path / "w.csv")
    truth = EFFECTS["infiltration"].apply(building, "EAST OFFICE", {"n": 1.2})
    airs = [z.air_node for z in building.zones]
    times = pd.date_range("2017-04-03 00:00", periods=5 * 24 + 1, freq="h", tz="-07:00", name="time")
    measured = pseudo_measurements(truth, weather, times, airs, noise_sd=0.05, seed=1, history_days=14)
    case = prepare_case(building, weather, measured, history_days=14).with_burn_in(1)
    objective = Objective.of(building, [z.name for z in building.zones])
    report = diagnose(building, case, tmp_path / "out", objective,
                      search=SearchSettings(seed=0, population=12, generations=10),
                      execution=Execution(fmu_kind="python")).to_json()
    after = json.loads((tmp_path / "out" / "building_after.json").read_text())
    east = next(z for z in after["zones"] if z["name"] == "EAST OFFICE")
    assert east["air_change_rate"] == pytest.approx(1.2, abs=0.05)
    for z in after["zones"]:
        if z["name"] != "EAST OFFICE":
            assert z["air_change_rate"] == pytest.approx(0.3)
    assert report["after"]["validation"]["rmse"] < report["before"]["validation"]["rmse"] / 3


def test_case600_corrections_written_back(tmp_path):
    """Case 600 converted; a record made by `nodeforce synth` with 1.2 air changes an hour where
    the IDF says 0.5; the diagnosis writes model_after.idf with the zone's infiltration object
    changed, every other object as written, and report.md names the change."""
    import idfkit
    from nodeforce.cli import main
    from nodeforce.iotools.measurements import read_measurements
    idf = ROOT / "examples" / "bestest" / "case600.idf"
    building = convert_idf(idf, tmp_path / "600.json")
    typical_year(tmp_path)
    assert main(["synth", str(tmp_path / "600.json"), "--weather", str(tmp_path / "w.csv"), "--start",
                 "2017-03-06T00:00-07:00", "--days", "5", "--step", "3600", "--sensors",
                 str(building.zones[0].air_node), "--noise", "0.05", "--effect", "infiltration@CASE 600 ZONE:n=1.2",
                 "-o", str(tmp_path / "m.csv")]) == 0
    weather, measured = read_weather(tmp_path / "w.csv"), read_measurements(tmp_path / "m.csv")
    case = prepare_case(building, weather, measured, history_days=14).with_burn_in(1)
    report = diagnose(building, case, tmp_path / "out", Objective.of(building),
                      search=SearchSettings(seed=0, population=12, generations=10),
                      execution=Execution(fmu_kind="python")).to_json()
    assert report["effect"]["effect"] == "infiltration"
    doc = idfkit.load_idf(str(tmp_path / "out" / "model_after.idf"))
    infiltration = doc.getobject("ZONEINFILTRATION:DESIGNFLOWRATE", "INFILTRATION")
    assert float(infiltration.air_changes_per_hour) == pytest.approx(1.2, abs=0.05)
    (change,) = report["energyplus"]["changes"]
    assert (change["object"], change["field"], change["old"]) == (
        "ZoneInfiltration:DesignFlowRate", "air_changes_per_hour", 0.5)
    assert "ZoneInfiltration:DesignFlowRate INFILTRATION, air_changes_per_hour: 0.5 ->" in (
        tmp_path / "out" / "report.md").read_text()
    # every other object as written: the IDF's text outside that object unchanged
    original = idf.read_text(encoding="latin-1").splitlines()
    written = (tmp_path / "out" / "model_after.idf").read_text(encoding="latin-1").splitlines()
    assert len(original) == len(written)
    assert sum(a != b for a, b in zip(original, written)) <= 12


def test_python_fmu_steps_the_scheduled_flows_as_the_direct_model(tmp_path):
    """The three zones' FMU (schedules as inputs, the corridor's night ventilation switched) gives
    the direct model's numbers, forced nodes included."""
    import numpy as np
    from nodeforce.cosim.fmi import FmuInstance
    from nodeforce.cosim.run import simulate_fmu
    from nodeforce.fmu_build.build import build_fmu
    from nodeforce.model.integrate import simulate
    from nodeforce.model.network import assemble
    building = convert_idf(ROOT / "examples" / "multizone" / "three_zones.idf")
    typical_year(tmp_path)
    weather = read_weather(tmp_path / "w.csv")
    airs = [z.air_node for z in building.zones]
    times = pd.date_range("2017-04-03 00:00", periods=2 * 24 * 4 + 1, freq="15min", tz="-07:00", name="time")
    measured = pseudo_measurements(building, weather, times, airs, spinup_days=2)
    case = prepare_case(building, weather, measured)
    force = np.zeros(building.n_nodes, dtype=bool)
    force[airs[0] - 1] = True
    direct = simulate(building, assemble(building), case.U, case.dt, case.measured, force, substeps=case.substeps)
    with FmuInstance(build_fmu(building, tmp_path / "three.fmu")) as instance:
        through_fmu = simulate_fmu(instance, case, force)
    assert np.abs(through_fmu - direct).max() < 1e-9
    corridor = building.zone("CORRIDOR").air_node - 1
    assert np.ptp(direct[:, corridor]) > 2.0
