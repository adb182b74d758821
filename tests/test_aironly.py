"""Records with ordinary sensors (issue 17): the indoor air, the weather and the heating power.

Every command takes them; `locate` says it has nothing to force; the candidate policy points at
the zone effects of docs/model.md section 7 where the residual asks for them, and the diagnosis
recovers each from an air-only synthetic record; the report gives the heat loss coefficient;
weather with `ghi` alone is split by a pvlib decomposition."""
import json
from dataclasses import replace

import numpy as np
import pandas as pd
import pvlib
import pytest

from nodeforce.diagnosis.candidates import physical
from nodeforce.diagnosis.loop import diagnose
from nodeforce.ga.locate import Execution, SearchSettings
from nodeforce.diagnosis.loss import heat_loss
from nodeforce.diagnosis.policy import Policy
from nodeforce.diagnosis.result import CrossValidation, Fit
from nodeforce.diagnosis.report.tables import before_after_table
from nodeforce.ga.locate import Localization, locate
from nodeforce.model.building_file import parse_building
from nodeforce.model.case import prepare_case
from nodeforce.model.effects import EFFECTS
from nodeforce.model.errors import InputError
from nodeforce.model.hlc import heat_loss_coefficient
from nodeforce.model.integrate import simulate
from nodeforce.model.network import assemble
from nodeforce.model.score import Objective
from nodeforce.model.solar import DECOMPOSITIONS, solar_position
from nodeforce.model.synth import pseudo_measurements

from .conftest import record_times

NOISE = 0.1  # C
HEATER = 500.0  # W


@pytest.fixture(scope="module")
def heated(testcell_data):
    """The test cell with a declared, measured heat input to its air."""
    return parse_building({**testcell_data, "zones": [dict(testcell_data["zones"][0], heat_input="Q_heat")]})


@pytest.fixture(scope="module")
def heated_weather(weather):
    """The bundled weather at 30 min (linear between its hours) with an on/off heater switching at
    each step with probability 0.15 (a pseudo-random binary sequence, as in-situ tests use)."""
    hours = weather.loc["2001-06-01":"2001-06-20"]
    grid = pd.date_range(hours.index[0], hours.index[-1], freq="30min", name="time")
    fine = hours.reindex(hours.index.union(grid)).interpolate("time").reindex(grid)
    rng = np.random.default_rng(7)
    fine["Q_heat"] = HEATER * (np.cumsum(rng.random(len(fine)) < 0.15) % 2)
    fine.attrs["source"] = "heated_weather.csv"
    return fine


def air_only(building, weather, days=5, **effect):
    """The case of `building` on an air-only record (node 23, 0.1 C noise) of the building with
    `effect` (id, values) that its file does not declare."""
    truth = EFFECTS[effect["id"]].apply(building, "cell", effect["values"]) if effect else building
    times = pd.date_range("2001-06-10T00:00-05:00", periods=days * 48 + 1, freq="30min", name="time")
    measurements = pseudo_measurements(truth, weather, times, [23], noise_sd=NOISE, seed=1)
    return truth, prepare_case(building, weather, measurements)


# -- every command takes a record of the air alone ------------------------------------------

def test_locate_with_nothing_to_force_says_so_and_finds_no_node(heated, heated_weather, tmp_path):
    _, case = air_only(heated, heated_weather, days=2)
    located = locate(heated, case, tmp_path, Objective.of(heated))
    result = located.to_json()
    assert result["best_nodes"] == [] and result["chromosome_nodes"] == [] and result["node_scores"] == {}
    assert result["J_best"] == result["J_unforced"] > 0
    assert result["finding"].startswith("No forcing can be tested")
    assert result["finding"].count(". ") == 0  # one sentence
    assert "roof (node 9)" in result["finding"]  # the largest surface facing the air, where a sensor helps
    summary = located.summary()
    (tmp_path / "locate.json").write_text(json.dumps(result))
    assert Localization.read(tmp_path / "locate.json") == located
    assert "J forced alone" not in summary and "best nodes: none" in summary


def test_locate_lists_the_one_scored_node_even_when_it_lowers_nothing():
    result = {"J_unforced": 3.0, "objective": ["cell"], "node_scores": {"7": 3.2}, "ranked_nodes": [],
              "best_nodes": [], "J_best": 3.0, "finding": "No forcing lowers J.",
              "search": {"method": "exhaustive", "unique_evaluations": 2, "seconds": 0.1}}
    lines = Localization.of({"measured_nodes": [7, 23], "output_node": 23, "output_nodes": [23], "chromosome_nodes": [7],
                             "tied_nodes": [], "noise": {}, "components": [], **result}).summary().splitlines()
    header = next(i for i, line in enumerate(lines) if "J forced alone" in line)
    assert lines[header + 1].split() == ["7", "3.200"]


def test_a_heat_power_in_the_measurements_is_told_it_names_no_node(heated, heated_weather):
    _, case = air_only(heated, heated_weather, days=2)
    times = case.times
    measured = pd.DataFrame({"T23": case.measured[:, 22], "Q_heat": HEATER}, index=times)
    measured.attrs["source"] = "measured.csv"
    with pytest.raises(InputError, match="names no node.*belongs in the weather file") as caught:
        prepare_case(heated, heated_weather, measured)
    assert caught.value.field == "Q_heat"
    # a sensor-named column still gets the kelvin check, once the building says it is a temperature
    named = heated.edited(lambda d: d.update(sensors={"room": {"zone": "cell"}}))
    kelvin = pd.DataFrame({"room": case.measured[:, 22] + 273.15}, index=times)
    kelvin.attrs["source"] = "kelvin.csv"
    with pytest.raises(InputError, match="Kelvin"):
        prepare_case(named, heated_weather, kelvin)


# -- the candidate policy -------------------------------------------------------------------

def test_an_air_only_record_calibrates_every_zone_effect_and_every_component(heated):
    """Nothing to force, so nothing points anywhere: every round calibrates the zone's effects
    (the heater's among them) and every component's, whatever the residual follows; the issue's
    furniture record left `internal_mass` untried because its residual followed the clock."""
    pairs = physical(heated, [], ["cell"], [23], Policy())
    assert {("internal_mass", "cell"), ("heat_input_lag", "cell"), ("heat_input_split", "cell"),
            ("envelope_conductance", "cell"), ("infiltration", "cell")} <= set(pairs)
    assert ("ground_coupling", "floor") in pairs and ("conductivity", "door") in pairs


# -- the heat loss coefficient in the report ------------------------------------------------

def record(effect, hlc, sd, J):
    """A round-1 candidate's fit of cross-validated J `J` (C2, one block) that makes the HLC `hlc`
    +- `sd` (W/K)."""
    return Fit(effect, "cell", {}, {"heat_loss_coefficient": {"value": hlc, "std": sd}}, {}, CrossValidation([J], 100))


def test_the_report_says_when_the_data_fix_the_loss_but_not_its_split(heated):
    """Infiltration and the envelope factor both move the loss to ~31 W/K and fit alike: the
    split is not the record's. A gain that fits as well moves no loss and is not part of it; a
    convection change whose HLC the data do not fix is not either."""
    before = heat_loss_coefficient(heated)
    envelope = EFFECTS["envelope_conductance"].apply(heated, "cell", {"factor": 1.5})
    hlc = heat_loss_coefficient(envelope)
    chosen = record("envelope_conductance", hlc, 0.02, 10.0)
    # 0.1 C of noise on 100 residuals: J may differ by 3 x 0.01 x sqrt(200) = 0.42 C2 by chance
    tried = [chosen, record("infiltration", hlc * 1.02, 0.06, 10.3), record("internal_gain", before, 0.0, 10.1),
             record("inside_convection", hlc * 1.03, 4.0, 10.2)]
    out = heat_loss(heated, envelope, [chosen], tried, 0.1, Policy().yardstick)
    assert out["before"] == pytest.approx(before) and out["after"] == pytest.approx(hlc)
    assert out["after_sd"] == 0.02
    assert "not how it splits" in out["split"] and "infiltration" in out["split"]
    assert "internal_gain" not in out["split"] and "inside_convection" not in out["split"]
    # an alternative that fits worse than the noise could make it, or loses differently, leaves
    # the split to the data
    tried[1] = replace(tried[1], cv=CrossValidation([11.0], 100))
    assert heat_loss(heated, envelope, [chosen], tried, 0.1, Policy().yardstick)["split"] is None
    tried[1] = replace(tried[1], cv=CrossValidation([10.3], 100),
                       derived={"heat_loss_coefficient": {"value": hlc * 1.2, "std": 0.06}})
    assert heat_loss(heated, envelope, [chosen], tried, 0.1, Policy().yardstick)["split"] is None
    report = {"effect": {"effect": "none"}, "before": {}, "after": {}, "objective": ["cell"],
              "heat_loss_coefficient": out, "assumptions": ["ghi split by erbs"]}
    table = before_after_table(report)
    assert f"Heat loss coefficient: {before:.1f} W/K as described" in table and "W/K as corrected" in table
    assert out["split"] in table and "assumed: ghi split by erbs" in table


# -- weather with the global irradiance alone -----------------------------------------------

def test_ghi_alone_is_split_as_pvlib_splits_it_and_the_split_is_stated(testcell, weather):
    """The roof's and the south wall's irradiance from ghi alone equal pvlib's Erbs (and DISC)
    decomposition then the isotropic transposition, called directly."""
    times = record_times(days=2)
    only_ghi = weather.drop(columns=["dni", "dhi"])
    only_ghi.attrs["source"] = "ghi.csv"
    site = testcell.site
    for model in ("erbs", "disc"):
        case = prepare_case(testcell, only_ghi, pd.DataFrame(index=times).assign(T23=np.nan), decomposition=model)
        assert any(model in a and "ghi" in a for a in case.assumptions)
        position = pvlib.solarposition.get_solarposition(times, site["latitude"], site["longitude"], site["altitude"])
        ghi = pd.Series(np.interp(times.asi8, only_ghi.index.asi8, only_ghi["ghi"]), index=times)
        if model == "erbs":
            split = pvlib.irradiance.erbs(ghi, position["zenith"], times)
            dni, dhi = split["dni"], split["dhi"]
        else:
            dni = pvlib.irradiance.disc(ghi, position["zenith"], times)["dni"]
            dhi = ghi - dni * np.cos(np.radians(position["zenith"]))
        for c in (testcell.component("roof"), testcell.component("south_wall")):
            poa = pvlib.irradiance.get_total_irradiance(c.tilt, c.azimuth, position["apparent_zenith"],
                                                        position["azimuth"], dni, ghi, dhi,
                                                        albedo=site["ground_albedo"], model="isotropic")["poa_global"]
            expected = np.where(np.isfinite(poa) & (poa > 0), poa, 0.0)
            got = case.U[:, case.input_names.index(f"I_{c.name}")]
            assert np.abs(got - expected).max() < 1e-6, (model, c.name)
            assert expected.max() > 100  # a sunny day
    full = prepare_case(testcell, weather, pd.DataFrame(index=times).assign(T23=np.nan))
    assert full.assumptions == ()  # nothing computed, nothing assumed
    assert set(DECOMPOSITIONS) >= {"erbs", "disc", "dirint"}


def test_weather_with_nothing_to_split_is_refused(testcell, weather):
    times = record_times(days=2)
    dark = weather.drop(columns=["ghi", "dni"])
    dark.attrs["source"] = "dark.csv"
    with pytest.raises(InputError, match="no global horizontal irradiance") as caught:
        prepare_case(testcell, dark, pd.DataFrame(index=times).assign(T23=np.nan))
    assert caught.value.source == "dark.csv" and caught.value.field == "ghi"
    # two of the three are enough: the third by closure, stated too
    case = prepare_case(testcell, weather.drop(columns=["dni"]), pd.DataFrame(index=times).assign(T23=np.nan))
    assert any("closure" in a for a in case.assumptions)


# -- recovery from air-only records ---------------------------------------------------------

RECOVERY = [("internal_mass", {"C_m": 1e6, "H_m": 80.0}),
            ("heat_input_lag", {"C_h": 6e4, "H_h": 25.0}),
            ("envelope_conductance", {"factor": 1.5})]


@pytest.mark.parametrize("effect,values", RECOVERY, ids=[e for e, _ in RECOVERY])
def test_the_steady_start_finds_the_walls_state_the_replay_alone_misses(heated, heated_weather, effect, values):
    """The records are made periodic by a year of replays of their first day (`pseudo_measurements`),
    an independent way to the walls' state at t_0. With the air alone measured, the true model
    started from the first day's steady state reproduces the record to two hundredths of a degree
    (over the burn-in, the air is forced to its samples linear in between, where the true air
    follows the heater's switching: the walls' state keeps a trace of that); the two replays of
    docs/model.md section 5 alone leave the heavy floor at the air's temperature, tenths of a
    degree off for the whole record."""
    truth = EFFECTS[effect].apply(heated, "cell", values)
    times = pd.date_range("2001-06-10T00:00-05:00", periods=5 * 48 + 1, freq="30min", name="time")
    record = pseudo_measurements(truth, heated_weather, times, [23])
    case = prepare_case(truth, heated_weather, record).with_burn_in(1)
    network = assemble(truth)

    def error(steady_start):
        T = simulate(truth, network, case.U, case.dt, case.measured, burn_in_steps=case.burn_in_steps,
                     steady_start=steady_start, substeps=case.substeps)
        return np.abs(record["T23"].to_numpy()[1:] - T[:, 22])[case.burn_in_steps:].max()
    assert error(True) < 0.02 < 0.1 < error(False)


@pytest.mark.slow  # a diagnosis each
@pytest.mark.parametrize("effect,values", RECOVERY, ids=[e for e, _ in RECOVERY])
def test_an_air_only_record_names_the_undeclared_zone_effect(heated, heated_weather, tmp_path, effect, values):
    """The test cell with a declared, measured on/off heater, only its air measured (0.1 C): the
    effect the file lacks is the one named, and nothing on top of it; the validation error falls
    to the noise; its parameters are the truth's within 3 of their standard deviations; the HLC
    as corrected is the truth's (the issue asks 10 %; the diagnosis starts the unmeasured walls
    from the first day's steady state, so no initial-state bias is left for a slow parameter to
    absorb)."""
    truth, case = air_only(heated, heated_weather, id=effect, values=values)
    report = diagnose(heated, case.with_burn_in(1), tmp_path, Objective.of(heated),
                      search=SearchSettings(noise=NOISE), execution=Execution(workers=2)).to_json()
    assert [(e["effect"], e["target"]) for e in report["effects"]] == [(effect, "cell")], report["decision"]["reason"]
    first = report["effects"][0]
    assert report["after"]["validation"]["rmse"] < 1.2 * NOISE < 2 * NOISE < report["before"]["validation"]["rmse"]
    for name, true in values.items():
        p = first["parameters"][name]
        assert p["identifiable"] and abs(p["value"] - true) < 3 * p["std"], (name, p, true)
    hlc = report["heat_loss_coefficient"]
    assert hlc["after"] == pytest.approx(heat_loss_coefficient(truth), rel=0.02)
    assert hlc["before"] == pytest.approx(heat_loss_coefficient(heated))
